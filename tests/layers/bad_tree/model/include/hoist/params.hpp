// fixture: a model header

// fixture: a tools/ header

// fixture: a tool header

// fixture: a daemon header

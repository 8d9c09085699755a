// fixture: a tool's own header, named like a daemon header

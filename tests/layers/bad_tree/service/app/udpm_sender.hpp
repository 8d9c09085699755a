// fixture: a daemon header whose name a tool also uses for its own

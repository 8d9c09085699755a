// fixture: a daemon header in a library folder of service/ (service/<lib>/include)

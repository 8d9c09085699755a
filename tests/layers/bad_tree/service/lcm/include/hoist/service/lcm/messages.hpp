// fixture: a service/lcm header

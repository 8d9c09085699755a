// fixture: a service/core header

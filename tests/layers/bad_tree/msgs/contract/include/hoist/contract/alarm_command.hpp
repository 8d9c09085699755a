// fixture: the daemon-client contract

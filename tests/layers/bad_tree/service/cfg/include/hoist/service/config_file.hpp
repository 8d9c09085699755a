// fixture: a public header of service/cfg outside its folder (hoist/service/cfg/)

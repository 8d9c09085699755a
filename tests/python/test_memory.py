"""Reference counts: a million small calls do not grow the process's memory."""
import gc

import hoist


def rss_kib():
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    raise RuntimeError("no VmRSS in /proc/self/status")


def test_a_million_small_calls_keep_memory_flat():
    cfg = hoist.Config.paper()
    for _ in range(20000):  # warm up: allocator pools, interned strings
        cfg.get("load.eccentric_force")
        cfg.get("guide_ropes.preload")
    gc.collect()
    before = rss_kib()
    for i in range(1_000_000):
        cfg.get("load.eccentric_force")
        if i % 100 == 0:
            cfg.get("guide_ropes.preload")
            cfg.set("cage.mass", 800.0 + (i % 7))
    gc.collect()
    grown = rss_kib() - before
    # A leaked reference per call would be >= 24 MB (1e6 floats of 24 B); allow 4 MB of noise.
    assert grown < 4096, f"RSS grew by {grown} KiB over a million calls"


def test_results_are_freed():
    cfg = hoist.Config.paper()
    for _ in range(5):
        hoist.simulate(cfg, t_end=5.0, modes=4)
    gc.collect()
    before = rss_kib()
    for _ in range(200):
        r = hoist.simulate(cfg, t_end=5.0, modes=4)  # 12 arrays of 501 doubles: 48 kB each time
        del r
    gc.collect()
    assert rss_kib() - before < 4096

#!/usr/bin/env python3
"""Write the seed corpora of fuzz_msgs and fuzz_lcmlog (fuzz/corpus/msgs,
fuzz/corpus/lcmlog) from msgs/*.lcm: a minimal and a filled valid encoding of
every type, and the known attack cases (string lengths 0, 0x80000000,
huge/negative counts, a log event with datalen 0x7fffffff, a corrupted event
in the middle of a log).  Run from the repository root; re-run when a type
changes (the committed seeds stay valid inputs either way)."""
import glob
import os
import struct
import sys

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "msgs", "codec"))
import lcm_codec_gen as g  # noqa: E402

FMT = {"int8_t": ">b", "int16_t": ">h", "int32_t": ">i", "int64_t": ">q", "byte": ">B",
       "float": ">f", "double": ">d", "boolean": ">b"}


def encode(st, count=0, text=b"", overrides=None):
    """Encoding of `st` with every var count = `count`, strings = `text`
    (nested values too, without fingerprints as lcm-gen writes them).
    overrides: member name -> raw bytes replacing that member's encoding
    (top level), or (nested member name, index, inner member name) -> bytes
    for a member of one nested element."""
    return struct.pack(">q", g.fingerprint(st)) + body(st, count, text, overrides)


def body(st, count=0, text=b"", overrides=None):
    out = b""
    for m in st.members:
        if overrides and m.name in overrides:
            out += overrides[m.name]
            continue
        n = 1
        if m.dims:
            mode, size = m.dims[0]
            n = int(size) if mode == 0 else count
        is_count = any(x.dims and x.dims[0] == (1, m.name) for x in st.members)
        for i in range(n):
            if m.nested:
                inner = {k[2]: v for k, v in (overrides or {}).items()
                         if isinstance(k, tuple) and k[0] == m.name and k[1] == i}
                out += body(m.struct, count, text, inner)
            elif m.type == "string":
                out += struct.pack(">i", len(text) + 1) + text + b"\0"
            elif is_count:
                out += struct.pack(FMT[m.type], count)
            else:
                out += struct.pack(FMT[m.type], 1 if m.type == "boolean" else 0)
    return out


def log_event(num, ch, data, datalen=None):
    dl = len(data) if datalen is None else datalen
    return struct.pack(">IqqiI", 0xEDA1DA01, num, 1000000 + num, len(ch), dl & 0xFFFFFFFF) + ch + data


def main():
    root = os.path.join(os.path.dirname(__file__), "..")
    structs = sorted(g.load(sorted(glob.glob(os.path.join(root, "msgs", "*.lcm")))), key=lambda s: s.full)
    mdir = os.path.join(root, "fuzz", "corpus", "msgs")
    ldir = os.path.join(root, "fuzz", "corpus", "lcmlog")
    os.makedirs(mdir, exist_ok=True)
    os.makedirs(ldir, exist_ok=True)
    seeds = {}
    events = []
    for k, st in enumerate(structs):
        seeds[f"{st.name}_min"] = bytes([k]) + encode(st)
        seeds[f"{st.name}_filled"] = bytes([k]) + encode(st, count=3, text=b"CAGE_POS_Y")
        events.append((st.name.upper().encode(), encode(st, count=2, text=b"x")))
        for m in st.members:
            if m.type == "string" and not m.dims:
                for bad in (0, 0x80000000, 0xFFFFFFFF):
                    seeds[f"{st.name}_{m.name}_len{bad:x}"] = bytes([k]) + encode(
                        st, overrides={m.name: struct.pack(">I", bad)})
            if m.dims and m.dims[0][0] == 1:
                cname = m.dims[0][1]
                cfmt = FMT[next(x.type for x in st.members if x.name == cname)]
                for bad in (0x7FFFFFFF, -1, -0x80000000, 100001):
                    bits = 8 * struct.calcsize(cfmt)
                    v = ((bad + (1 << (bits - 1))) % (1 << bits)) - (1 << (bits - 1))  # wrap to the count's width
                    seeds[f"{st.name}_{cname}_{bad & 0xFFFFFFFF:x}"] = bytes([k]) + encode(
                        st, overrides={cname: struct.pack(cfmt, v)})
            if m.nested and m.dims:
                # Bad counts and strings inside the second nested element
                # (forecast_t.scenarios[1].num_points, .name).
                for x in m.struct.members:
                    if x.dims and x.dims[0][0] == 1:
                        cname = x.dims[0][1]
                        cfmt = FMT[next(y.type for y in m.struct.members if y.name == cname)]
                        for bad in (-1, 0x7FFF if cfmt != ">b" else 0x7F, 65):
                            seeds[f"{st.name}_{m.name}1_{cname}_{bad & 0xFFFF:x}"] = bytes([k]) + encode(
                                st, count=2, text=b"estop",
                                overrides={(m.name, 1, cname): struct.pack(cfmt, bad)})
                    if x.type == "string" and not x.dims:
                        for bad in (0, 0x80000000):
                            seeds[f"{st.name}_{m.name}1_{x.name}_len{bad:x}"] = bytes([k]) + encode(
                                st, count=2, overrides={(m.name, 1, x.name): struct.pack(">I", bad)})
    for name, data in seeds.items():
        with open(os.path.join(mdir, name), "wb") as f:
            f.write(data)
    good = b"".join(log_event(i, ch, d) for i, (ch, d) in enumerate(events))
    logs = {
        "clean": good,
        "datalen_7fffffff": good + log_event(99, b"HOIST_WINDER", b"\0" * 49, 0x7FFFFFFF) + good,
        "corrupt_middle": good[:len(good) // 2] + b"\xff\xff\xff" + good[len(good) // 2:],
        "truncated_tail": good[:-5],
        "garbage_first": b"\x01\x02\x03" + good,
    }
    for name, data in logs.items():
        with open(os.path.join(ldir, name), "wb") as f:
            f.write(data)
    print(f"{len(seeds)} seeds in {mdir}, {len(logs)} in {ldir}")


if __name__ == "__main__":
    main()

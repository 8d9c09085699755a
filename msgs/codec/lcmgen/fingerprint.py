"""Step 2: each type's LCM fingerprint, with LCM's rules (lcmgen.c:
lcm_struct_hash + the rotation of _computeHash); tests/msgs checks that it
equals lcm-gen's getHash() for every type.  A nested type contributes its own
hash (recursively, as lcm-gen's _computeHash); nested values carry no
fingerprint of their own on the wire (lcm-gen's _encodeNoHash), so the outer
fingerprint covers them."""
from .model import PRIMITIVES

M64 = (1 << 64) - 1


def _s64(v):
    v &= M64
    return v - (1 << 64) if v >> 63 else v


def _hash_update(v, c):
    # v = ((v << 8) ^ (v >> 55)) + c with int64 v (arithmetic shift) and a
    # signed char c, as in lcmgen.c.
    c = c - 256 if c > 127 else c
    return _s64(((v << 8) ^ (v >> 55)) + c)


def _hash_string(v, s):
    b = s.encode()
    v = _hash_update(v, len(b) & 0xFF)
    for c in b:
        v = _hash_update(v, c)
    return v


def base_hash(st):
    """lcmgen.c lcm_struct_hash: member names, primitive type names, dims."""
    v = 0x12345678
    for m in st.members:
        v = _hash_string(v, m.name)
        if m.type in PRIMITIVES:
            v = _hash_string(v, m.type)
        v = _hash_update(v, len(m.dims))
        for mode, size in m.dims:
            v = _hash_update(v, mode)
            v = _hash_string(v, size)
    return v


def fingerprint(st, parents=()):
    """lcm-gen's getHash(): _computeHash = rotl1(base hash + the _computeHash
    of every nested member's type), 0 for a type already on the stack."""
    if st in parents:
        return 0
    u = base_hash(st) & M64
    for m in st.members:
        if m.nested:
            u = (u + (fingerprint(m.struct, parents + (st,)) & M64)) & M64
    return _s64((u << 1) + ((u >> 63) & 1))


def hex_fingerprint(st):
    """0x%016x of the fingerprint as an unsigned 64-bit number."""
    return f"0x{fingerprint(st) & M64:016x}"

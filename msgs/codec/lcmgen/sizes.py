"""The smallest and largest encoding of each type [bytes], from the member
types, fixed array sizes and the maxima of the variable ones (@max)."""
from .model import GLOBAL_MAX_SIZE, PRIM_SIZE


def elem_max(m):
    if m.nested:
        return body_max(m.struct)
    return 4 + m.max_len + 1 if m.type == "string" else PRIM_SIZE[m.type]


def elem_min(m):
    if m.nested:
        return body_min(m.struct)
    return 5 if m.type == "string" else PRIM_SIZE[m.type]


def body_max(st):
    """Largest encoding of st without its fingerprint (as nested), uncapped."""
    total = 0
    for m in st.members:
        count = 1
        for mode, size in m.dims:
            count *= int(size) if mode == 0 else m.max_count
        total += count * elem_max(m)
    return total


def body_min(st):
    """Smallest encoding of st without its fingerprint (as nested)."""
    total = 0
    for m in st.members:
        count = 1
        for mode, size in m.dims:
            count *= int(size) if mode == 0 else 0
        total += count * elem_min(m)
    return total


def max_size(st):
    return min(8 + body_max(st), GLOBAL_MAX_SIZE)


def min_size(st):
    return 8 + body_min(st)

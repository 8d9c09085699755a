"""The JSON Schema (draft 2020-12) of toJson(T)'s output, one per type."""
import json

from .fingerprint import hex_fingerprint
from .model import INT_RANGE, REAL_TYPES


def scalar_schema(m):
    if m.type == "string":
        return {"type": "string", "maxLength": m.max_len}
    if m.type == "boolean":
        return {"type": "boolean"}
    if m.type in REAL_TYPES:
        return {"type": ["number", "null"]}
    lo, hi = INT_RANGE[m.type]
    return {"type": "integer", "minimum": lo, "maximum": hi}


def schema_obj(st, top):
    props = {}
    maxima = {m.dims[0][1]: m.max_count for m in st.members if m.var_array}
    for m in st.members:
        s = schema_obj(m.struct, False) if m.nested else scalar_schema(m)
        if m.name in maxima:  # an array count: what checkedDecode accepts
            s["minimum"], s["maximum"] = 0, maxima[m.name]
        if m.dims:
            mode, size = m.dims[0]
            s = {"type": "array", "items": s}
            if mode == 0:
                s["minItems"] = s["maxItems"] = int(size)
            else:
                s["maxItems"] = m.max_count
        desc = m.desc
        if m.type in REAL_TYPES:
            desc = (desc + " " if desc else "") + "(null: not finite)"
        if m.var_array:
            desc = (desc + " " if desc else "") + f"(length: {m.dims[0][1]})"
        if desc and m.nested and not m.dims:
            s = {**s, "description": desc}  # the member's, over the type's
        elif desc:
            s = {"description": desc, **s}
        props[m.name] = s
    out = {}
    if top:
        out["$schema"] = "https://json-schema.org/draft/2020-12/schema"
        out["$id"] = f"urn:hoist-twin:msg:{st.full}"
    out.update({
        "title": st.full,
        "description": st.desc,
        "type": "object",
        "properties": props,
        "required": [m.name for m in st.members],
        "additionalProperties": False,
    })
    # Nested values carry no fingerprint on the wire; the type's own is
    # still given (it is what lcm-gen's getHash() returns for it).
    out["x-lcm-fingerprint"] = hex_fingerprint(st)
    if st.consts:
        out["x-lcm-constants"] = {n: (float(v) if t in REAL_TYPES else int(v, 0))
                                  for t, n, v in st.consts}
    return out


def schema(st):
    """JSON Schema of toJson(st): nested types are inlined (no $ref), so
    every consumer (Foxglove, the dashboard page) reads it without resolving."""
    return json.dumps(schema_obj(st, True), indent=2)

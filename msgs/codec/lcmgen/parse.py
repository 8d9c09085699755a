"""Step 1: the .lcm files -> Structs (model.py), with the annotations read
from their comments, checked, and nested member types linked."""
import re

from .model import (DEFAULT_MAX_COUNT, DEFAULT_MAX_STRING, DIM_TYPES, INT_RANGE, PRIMITIVES,
                    Enum, GenError, Member, Struct)

_ID = r"[A-Za-z_]\w*"

# Each annotation: its keyword and the whole of its valid form.  A comment
# that names a keyword (@max, @enum, ...) must hold it in that form.
ANNOTATIONS = {
    "max": rf"@max\s+({_ID})\s+(\d+|{_ID})",
    "maxlen": rf"@maxlen\s+({_ID})\s+(\d+)",
    "enum": rf"@enum\s+({_ID})\s+({_ID}_)(?![\w])",
    "csv": rf"@csv\s+({_ID})\s+({_ID})(?:\s+(\d+))?(?![\w])",
    "csvfirst": rf"@csvfirst\s+({_ID}(?:,{_ID})*)(?![\w,])",
    "channel": r"@channel\s+([A-Z][A-Z0-9_]*)(?![\w])",
    "group": r"@group\s+([a-z][a-z0-9_]*)(?![\w])",
}
_WANT = {
    "max": "'@max COUNT N|CONST'",
    "maxlen": "'@maxlen MEMBER N'",
    "enum": "'@enum MEMBER PREFIX_'",
    "csv": "'@csv MEMBER COLUMN [FIRST]'",
    "csvfirst": "'@csvfirst MEMBER,MEMBER,...'",
    "channel": "'@channel NAME' (upper case)",
    "group": "'@group name' (lower case, in the member's own line)",
}
_ANY_ANNOTATION = "|".join(f"(?:{p})" for p in ANNOTATIONS.values())


def tokenize(text):
    """Tokens with line numbers, plus a map line -> comment text, and the set
    of lines that hold only a comment."""
    toks, comments, comment_only = [], {}, set()
    i, line, n = 0, 1, len(text)
    line_has_code = False
    while i < n:
        c = text[i]
        if c == "\n":
            line += 1
            line_has_code = False
            i += 1
        elif c.isspace():
            i += 1
        elif text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            comments[line] = (comments.get(line, "") + " " + text[i + 2:j].strip()).strip()
            if not line_has_code:
                comment_only.add(line)
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            if j < 0:
                raise GenError(f"line {line}: unterminated /* comment")
            body = text[i + 2:j]
            for k, part in enumerate(body.split("\n")):
                part = part.strip().lstrip("*").strip()
                if part:
                    comments[line + k] = (comments.get(line + k, "") + " " + part).strip()
                if not line_has_code or k > 0:
                    comment_only.add(line + k)
            line += body.count("\n")
            i = j + 2
        elif c.isalnum() or c in "_.-+":
            j = i
            while j < n and (text[j].isalnum() or text[j] in "_.-+"):
                j += 1
            toks.append((text[i:j], line))
            line_has_code = True
            i = j
        elif c in "{}[];,=":
            toks.append((c, line))
            line_has_code = True
            i += 1
        else:
            raise GenError(f"line {line}: unexpected character {c!r}")
    return toks, comments, comment_only


def preceding_comment(line, comments, comment_only):
    parts = []
    k = line - 1
    while k in comment_only and k in comments:
        parts.insert(0, comments[k])
        k -= 1
    return " ".join(p for p in parts if not p.startswith("@"))


def describe(first, last, comments, comment_only):
    def clean(text):
        return re.sub(r"\s+", " ", re.sub(_ANY_ANNOTATION, "", text)).strip()
    trail = clean(" ".join(comments[k] for k in range(first, last + 1)
                           if k in comments and k not in comment_only))
    return trail or clean(preceding_comment(first, comments, comment_only))


def check_annotations(path, comments):
    for ln, c in comments.items():
        for kw in re.finditer(r"@(\w+)", c):
            key = kw.group(1)
            if key not in ANNOTATIONS:
                continue
            if not re.match(ANNOTATIONS[key], c[kw.start():]):
                raise GenError(f"{path}:{ln}: malformed annotation {c!r} (want {_WANT[key]})")


def read_annotations(st, comments, first_line, last_line):
    for ln in range(first_line, last_line + 1):
        c = comments.get(ln, "")
        for a in re.finditer(ANNOTATIONS["max"], c):
            st.max_annot[a.group(1)] = a.group(2)
        for a in re.finditer(ANNOTATIONS["maxlen"], c):
            st.maxlen_annot[a.group(1)] = int(a.group(2))
        for a in re.finditer(ANNOTATIONS["enum"], c):
            if a.group(1) in st.enum_annot:
                raise GenError(f"{st.path}:{ln}: {st.full}: second @enum for {a.group(1)!r}")
            st.enum_annot[a.group(1)] = a.group(2)
        for a in re.finditer(ANNOTATIONS["csv"], c):
            st.csv_annot[a.group(1)] = (a.group(2), int(a.group(3) or 0))
        for a in re.finditer(ANNOTATIONS["csvfirst"], c):
            if st.csv_first:
                raise GenError(f"{st.path}:{ln}: {st.full}: second @csvfirst")
            st.csv_first = a.group(1).split(",")
        for a in re.finditer(ANNOTATIONS["channel"], c):
            if st.channel:
                raise GenError(f"{st.path}:{ln}: {st.full}: second @channel")
            st.channel = a.group(1)


def member_group(path, st, m, comments, comment_only, first, last):
    """`// @group name` in the member's own line(s): the member is one of the
    counters one writer keeps (a generated struct per group, emit.py)."""
    found = None
    for ln in range(first, last + 1):
        if ln in comment_only:
            continue
        for a in re.finditer(ANNOTATIONS["group"], comments.get(ln, "")):
            if found and found != a.group(1):
                raise GenError(f"{path}:{ln}: {st.full}.{m.name}: two @group names")
            found = a.group(1)
    if found and (m.dims or m.type not in PRIMITIVES or m.type == "string"):
        raise GenError(f"{path}:{first}: {st.full}.{m.name}: @group is for scalar numbers and booleans only")
    return found


def parse_file(path):
    with open(path, encoding="utf-8") as f:
        text = f.read()
    toks, comments, comment_only = tokenize(text)
    check_annotations(path, comments)
    pos = 0

    def peek():
        return toks[pos][0] if pos < len(toks) else None

    def take(expect=None):
        nonlocal pos
        if pos >= len(toks):
            raise GenError(f"{path}: unexpected end of file")
        tok, ln = toks[pos]
        if expect is not None and tok != expect:
            raise GenError(f"{path}:{ln}: expected {expect!r}, found {tok!r}")
        pos += 1
        return tok, ln

    package = ""
    structs = []
    while pos < len(toks):
        tok, ln = take()
        if tok == "package":
            package, _ = take()
            take(";")
        elif tok == "struct":
            name, sln = take()
            st = Struct(package, name, preceding_comment(ln, comments, comment_only), path)
            take("{")
            while peek() != "}":
                tok, mln = take()
                if tok == "const":
                    ctype, _ = take()
                    while True:
                        cname, _ = take()
                        take("=")
                        val, _ = take()
                        st.consts.append((ctype, cname, val))
                        t2, _ = take()
                        if t2 == ";":
                            break
                        if t2 != ",":
                            raise GenError(f"{path}:{mln}: bad const declaration")
                    continue
                mtype = tok
                while True:
                    mname, _ = take()
                    dims = []
                    while peek() == "[":
                        take("[")
                        size, _ = take()
                        take("]")
                        dims.append((0 if size.isdigit() else 1, size))
                    t2, lastln = take()
                    m = Member(mtype, mname, dims, mln,
                               describe(mln, lastln, comments, comment_only))
                    m.group = member_group(path, st, m, comments, comment_only, mln, lastln)
                    st.members.append(m)
                    if t2 == ";":
                        break
                    if t2 != ",":
                        raise GenError(f"{path}:{mln}: expected ',' or ';' after member {mname}")
            _, eln = take("}")
            for k in range(sln, eln + 1):
                if k in comment_only and re.search(ANNOTATIONS["group"], comments.get(k, "")):
                    raise GenError(f"{path}:{k}: {st.full}: @group belongs in its member's own line")
            read_annotations(st, comments, sln, eln)
            check_struct(st)
            structs.append(st)
        else:
            raise GenError(f"{path}:{ln}: unexpected {tok!r} (only 'package' and 'struct' are supported)")
    return structs


def check_struct(st):
    where = f"{st.path}: {st.full}"
    seen = {}
    consts = {n: (t, v) for t, n, v in st.consts}

    def maximum(count):
        ann = st.max_annot.get(count)
        if ann is None:
            conv = "MAX_" + count[4:].upper() if count.startswith("num_") else None
            if conv in consts:
                ann = conv
        if ann is None:
            return DEFAULT_MAX_COUNT
        if ann.isdigit():
            return int(ann)
        if ann not in consts or consts[ann][0] not in DIM_TYPES:
            raise GenError(f"{where}: @max {count} {ann}: {ann!r} is not an integer const of the struct")
        v = int(consts[ann][1], 0)
        if v < 0:
            raise GenError(f"{where}: const {ann} = {v} is not a valid maximum")
        return v

    for m in st.members:
        if m.type not in PRIMITIVES and not re.fullmatch(r"[A-Za-z_]\w*(\.[A-Za-z_]\w*)?", m.type):
            raise GenError(f"{where}.{m.name}: bad member type {m.type!r}")
        if len(m.dims) > 1:
            raise GenError(f"{where}.{m.name}: multi-dimensional arrays are not supported by "
                           "lcm_codec_gen.py yet (extend it)")
        for mode, size in m.dims:
            if mode == 1:
                cm = seen.get(size)
                if cm is None or cm.type not in DIM_TYPES or cm.dims:
                    raise GenError(f"{where}.{m.name}: array size {size!r} is not an earlier "
                                   "integer member")
                m.max_count = maximum(size)
        if m.type == "string":
            m.max_len = st.maxlen_annot.get(m.name, DEFAULT_MAX_STRING)
        seen[m.name] = m
    for k in st.max_annot:
        if k not in seen:
            raise GenError(f"{where}: @max names unknown member {k!r}")
    for k in st.maxlen_annot:
        if k not in seen or seen[k].type != "string":
            raise GenError(f"{where}: @maxlen names {k!r}, which is not a string member")
    for k, prefix in st.enum_annot.items():
        m = seen.get(k)
        if m is None or m.dims or (m.type not in INT_RANGE and m.type != "string"):
            raise GenError(f"{where}: @enum names {k!r}, which is not a scalar integer or string member")
        m.enum = enum_of(st, k, prefix, consts, where)
        st.enums.append(m.enum)
    stems = [e.stem for e in st.enums]
    if len(set(stems)) != len(stems):
        raise GenError(f"{where}: two @enum prefixes give the same table name")
    for k, (col, first) in st.csv_annot.items():
        if k not in seen:
            raise GenError(f"{where}: @csv names unknown member {k!r}")
        seen[k].csv_name, seen[k].csv_first = col, first
        if first and not seen[k].dims:
            raise GenError(f"{where}: @csv {k} {col} {first}: a first index is for arrays only")
    for k in st.csv_first:
        if k not in seen:
            raise GenError(f"{where}: @csvfirst names unknown member {k!r}")
    if len(set(st.csv_first)) != len(st.csv_first):
        raise GenError(f"{where}: @csvfirst names a member twice")


def enum_of(st, member, prefix, consts, where):
    """The consts PREFIX_* of st as an Enum: integer consts whose values are
    distinct and consecutive (a name table indexed by value - first)."""
    items, types = [], set()
    for t, n, v in st.consts:
        if not n.startswith(prefix):
            continue
        if t not in INT_RANGE or not n[len(prefix):]:
            raise GenError(f"{where}: @enum {member} {prefix}: const {n} is not an integer const "
                           f"named {prefix}<NAME>")
        items.append((int(v, 0), n[len(prefix):]))
        types.add(t)
    if not items:
        raise GenError(f"{where}: @enum {member} {prefix}: the struct has no const {prefix}<NAME>")
    items.sort()
    first = items[0][0]
    values = [v for v, _ in items]
    if values != list(range(first, first + len(items))):
        raise GenError(f"{where}: @enum {member} {prefix}: the values {values} are not distinct "
                       "and consecutive")
    ctype = max(types, key=lambda t: INT_RANGE[t][1] - INT_RANGE[t][0])
    if ctype == "byte":
        ctype = "uint8_t"
    e = Enum(member, prefix, first, [n for _, n in items], ctype)
    if len(set(e.camel)) != len(e.camel) or any(not c[:1].isalpha() for c in e.camel):
        raise GenError(f"{where}: @enum {member} {prefix}: the names {e.names} give no distinct C++ "
                       "enumerators (CAGE_POS_Y -> CagePosY)")
    return e


def resolve(structs):
    """Link each nested member to its Struct (same package unless qualified);
    reject unknown and recursive types."""
    by_name = {s.full: s for s in structs}
    for st in structs:
        for m in st.members:
            if not m.nested:
                continue
            full = m.type if "." in m.type else (f"{st.package}.{m.type}" if st.package else m.type)
            m.struct = by_name.get(full)
            if m.struct is None:
                raise GenError(f"{st.path}: {st.full}.{m.name}: unknown type {m.type!r} (not in the .lcm files given)")

    def visit(st, stack):
        if st in stack:
            raise GenError(f"{st.path}: {st.full}: recursive type ({' -> '.join(x.full for x in stack + [st])}) "
                           "is not supported")
        for m in st.members:
            if m.nested:
                visit(m.struct, stack + [st])
    for st in structs:
        visit(st, [])


def load(files):
    structs = []
    for f in files:
        structs.extend(parse_file(f))
    resolve(structs)
    return structs

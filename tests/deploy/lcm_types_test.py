#!/usr/bin/env python3
"""The hoist LCM types work from every language lcm-gen targets.

  lcm_types_test.py reserved MSGS_DIR
      every package, struct, field and constant name of msgs/*.lcm is checked
      against the reserved words of C, C++, Java, Python, Lua, C# and Go, and
      against the member names lcm-gen itself generates (encode, decode, ...).
  lcm_types_test.py python MSGS_DIR WORK_DIR
      lcm-gen -p, then python3 imports every type, fills every field,
      encodes, decodes and compares (the generated types need no `lcm`
      module for that; Debian ships no python3-lcm).
  lcm_types_test.py java MSGS_DIR WORK_DIR [LCM_JAR]
      lcm-gen -j, then javac against Debian's lcm.jar (exit 77 = skipped
      when javac or lcm.jar is missing).
"""
import glob
import importlib
import os
import re
import shutil
import subprocess
import sys

RESERVED = {
    "C": """auto break case char const continue default do double else enum extern float for goto if inline int
        long register restrict return short signed sizeof static struct switch typedef union unsigned void volatile
        while _Alignas _Alignof _Atomic _Bool _Complex _Generic _Imaginary _Noreturn _Static_assert _Thread_local
        bool true false alignas alignof static_assert thread_local typeof nullptr constexpr""",
    "C++": """alignas alignof and and_eq asm auto bitand bitor bool break case catch char char8_t char16_t char32_t class
        compl concept const consteval constexpr constinit const_cast continue co_await co_return co_yield decltype
        default delete do double dynamic_cast else enum explicit export extern false float for friend goto if inline
        int long mutable namespace new noexcept not not_eq nullptr operator or or_eq private protected public register
        reinterpret_cast requires return short signed sizeof static static_assert static_cast struct switch template
        this thread_local throw true try typedef typeid typename union unsigned using virtual void volatile wchar_t
        while xor xor_eq final override import module""",
    "Java": """abstract assert boolean break byte case catch char class const continue default do double else enum
        extends final finally float for goto if implements import instanceof int interface long native new package
        private protected public return short static strictfp super switch synchronized this throw throws transient
        try void volatile while true false null var yield record sealed permits non-sealed""",
    "Python": """False None True and as assert async await break class continue def del elif else except finally for
        from global if import in is lambda nonlocal not or pass raise return try while with yield match case type""",
    "Lua": """and break do else elseif end false for function goto if in local nil not or repeat return then true until
        while""",
    "C#": """abstract as base bool break byte case catch char checked class const continue decimal default delegate do
        double else enum event explicit extern false finally fixed float for foreach goto if implicit in int interface
        internal is lock long namespace new null object operator out override params private protected public readonly
        ref return sbyte sealed short sizeof stackalloc static string struct switch this throw true try typeof uint
        ulong unchecked unsafe ushort using virtual void volatile while""",
    "Go": """break case chan const continue default defer else fallthrough for func go goto if import interface map
        package range return select struct switch type var""",
}
# Names the generated code itself defines on each type (a field of the same
# name would shadow or clash with them).
GENERATED = """encode decode copy encodedSize getHash getTypeName _encode_one _decode_one _get_hash_recursive
    _get_packed_fingerprint _packed_fingerprint _hash _encodeNoHash _decodeNoHash _computeHash _getEncodedSizeNoHash
    LCM_FINGERPRINT LCM_FINGERPRINT_BASE __slots__ __init__ __typenames__ __dimensions__ outs ins""".split()


def parse(path):
    """(package, struct, [(kind, name, type, dims)]) of one .lcm file (our files' subset of the grammar)."""
    text = re.sub(r"//[^\n]*", "", open(path).read())
    text = re.sub(r"/\*.*?\*/", "", text, flags=re.S)
    pkg = re.search(r"package\s+(\w+)\s*;", text).group(1)
    m = re.search(r"struct\s+(\w+)\s*\{(.*)\}", text, re.S)
    struct, body = m.group(1), m.group(2)
    members = []
    for stmt in body.split(";"):
        stmt = " ".join(stmt.split())
        if not stmt:
            continue
        if stmt.startswith("const "):
            _, typ, rest = stmt.split(" ", 2)
            for part in rest.split(","):
                members.append(("const", part.split("=")[0].strip(), typ, []))
        else:
            typ, rest = stmt.split(" ", 1)
            for decl in rest.split(","):
                name = decl.split("[")[0].strip()
                dims = re.findall(r"\[\s*(\w+)\s*\]", decl)
                members.append(("field", name, typ, dims))
    return pkg, struct, members


def lcm_files(msgs):
    files = sorted(glob.glob(os.path.join(msgs, "*.lcm")))
    if not files:
        sys.exit(f"no .lcm files in {msgs}")
    return files


def reserved(msgs):
    words = {lang: set(w.split()) for lang, w in RESERVED.items()}
    bad, count = [], 0
    for f in lcm_files(msgs):
        pkg, struct, members = parse(f)
        names = [("package", pkg), ("struct", struct)] + [(k, n) for k, n, _, _ in members]
        for kind, name in names:
            count += 1
            for lang, ws in words.items():
                # C, C#, Lua, Python are case-sensitive like the rest; check as written.
                if name in ws:
                    bad.append(f"{os.path.basename(f)}: {kind} `{name}` is a {lang} reserved word")
            if name in GENERATED:
                bad.append(f"{os.path.basename(f)}: {kind} `{name}` clashes with a member lcm-gen generates")
    for b in bad:
        print("FAIL " + b)
    print(f"{count} names in {len(lcm_files(msgs))} files checked against {', '.join(RESERVED)}: "
          f"{len(bad)} problem(s)")
    return 1 if bad else 0


def sample(typ, i):
    return {"int8_t": 7, "int16_t": -300, "int32_t": 70000, "int64_t": 2**40 + i, "float": 0.5, "double": 1.25 + i,
            "boolean": True, "string": f"s{i}", "byte": 9}.get(typ)


def python(msgs, work):
    out = os.path.join(work, "python")
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(out)
    subprocess.run(["lcm-gen", "-p", "--ppath", out] + lcm_files(msgs), check=True)
    sys.path.insert(0, out)
    bad = 0
    parsed = {}
    for f in lcm_files(msgs):
        pkg, struct, members = parse(f)
        parsed[struct] = (pkg, members)

    def build(struct):
        """An instance of `struct` with every field filled (nested types
        recursively, e.g. forecast_t.scenarios)."""
        pkg, members = parsed[struct]
        cls = getattr(importlib.import_module(f"{pkg}.{struct}"), struct)
        msg = cls()
        sizes = {}
        dim_names = {d for _, _, _, dims in members for d in dims if not d.isdigit()}
        for i, (kind, name, typ, dims) in enumerate(members):
            if kind != "field":
                continue
            nested = typ.split(".")[-1] if typ.split(".")[-1] in parsed else None
            if not dims:
                value = build(nested)[1] if nested else (2 if name in dim_names else sample(typ, i))  # sizes: small
                setattr(msg, name, value)
                sizes[name] = value
            else:
                n = int(dims[0]) if dims[0].isdigit() else sizes[dims[0]]
                setattr(msg, name, [build(nested)[1] for _ in range(n)] if nested else [sample(typ, i)] * n)
        return cls, msg

    for f in lcm_files(msgs):
        pkg, struct, members = parse(f)
        cls, msg = build(struct)  # a keyword field fails right here at import (SyntaxError)
        data = msg.encode()
        back = cls.decode(data)
        prim = [(n, t) for k, n, t, _ in members if k == "field" and t.split(".")[-1] not in parsed]
        same = back.encode() == data and all(
            getattr(back, n) == getattr(msg, n) or
            (isinstance(getattr(msg, n), list) and list(getattr(back, n)) == getattr(msg, n))
            for n, _ in prim)
        print(("ok   " if same else "FAIL ") + f"python: import {pkg}.{struct}, encode {len(data)} bytes, decode"
              f" {'equal' if same else 'DIFFERENT'}; fingerprint {cls._get_packed_fingerprint().hex()}")
        bad += 0 if same else 1
    return 1 if bad else 0


def java(msgs, work, jar):
    javac = shutil.which("javac")
    if not javac or not os.path.exists(jar):
        print(f"SKIP: javac ({javac}) or {jar} missing (packages default-jdk-headless, liblcm-java)")
        return 77
    out = os.path.join(work, "java")
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(os.path.join(out, "classes"))
    subprocess.run(["lcm-gen", "-j", "--jpath", os.path.join(out, "src")] + lcm_files(msgs), check=True)
    srcs = sorted(glob.glob(os.path.join(out, "src", "**", "*.java"), recursive=True))
    r = subprocess.run([javac, "-Xlint:none", "-cp", jar, "-d", os.path.join(out, "classes")] + srcs)
    classes = glob.glob(os.path.join(out, "classes", "**", "*.class"), recursive=True)
    ok = r.returncode == 0 and len(classes) >= len(srcs)
    print(("ok   " if ok else "FAIL ") + f"java: {len(srcs)} sources compiled against {jar} -> {len(classes)} classes")
    return 0 if ok else 1


if __name__ == "__main__":
    mode = sys.argv[1]
    if mode == "reserved":
        sys.exit(reserved(sys.argv[2]))
    if mode == "python":
        sys.exit(python(sys.argv[2], sys.argv[3]))
    if mode == "java":
        sys.exit(java(sys.argv[2], sys.argv[3], sys.argv[4] if len(sys.argv) > 4 else "/usr/share/java/lcm.jar"))
    sys.exit(__doc__)

#!/usr/bin/env python3
"""lcm_codec_gen.py on bad annotations: exit status 2 and a message naming
the file and the thing that is wrong, nothing written.  Also: a good
@enum / @csv / @channel set is accepted.
  codec_gen_errors_test.py SOURCE_DIR WORK_DIR"""
import os
import subprocess
import sys

src, work = sys.argv[1], sys.argv[2]
gen = os.path.join(src, "msgs", "codec", "lcm_codec_gen.py")
os.makedirs(work, exist_ok=True)
passed = failed = 0


def run(name, body, want_rc, want_text=""):
    global passed, failed
    path = os.path.join(work, f"{name}.lcm")
    with open(path, "w") as f:
        f.write("package hoist;\n" + body)
    out = os.path.join(work, f"out_{name}")
    r = subprocess.run([sys.executable, gen, "--out", out, path], capture_output=True, text=True)
    ok = r.returncode == want_rc and want_text in r.stderr and (want_rc == 0) == os.path.exists(out)
    if want_rc != 0:
        ok = ok and f"{name}.lcm" in r.stderr
    print(f"{'ok  ' if ok else 'FAIL'} {name}: rc {r.returncode} {r.stderr.strip()}")
    passed, failed = passed + ok, failed + (not ok)


run("gap_t", "struct gap_t {\n  int8_t level;  // @enum level LEVEL_\n"
    "  const int8_t LEVEL_A = 0, LEVEL_B = 2;\n}\n", 2, "not distinct and consecutive")
run("noconst_t", "struct noconst_t {\n  int8_t level;  // @enum level LEVEL_\n}\n", 2, "no const LEVEL_<NAME>")
run("arr_t", "struct arr_t {\n  int8_t level[2];  // @enum level LEVEL_\n  const int8_t LEVEL_A = 0;\n}\n", 2,
    "not a scalar integer or string member")
run("real_t", "struct real_t {\n  double x;  // @enum x X_\n  const int8_t X_A = 0;\n}\n", 2,
    "not a scalar integer or string member")
run("badform_t", "struct badform_t {\n  int8_t level;  // @enum level\n}\n", 2, "malformed annotation")
run("csvunknown_t", "struct csvunknown_t {\n  int8_t a;  // @csv b c\n}\n", 2, "@csv names unknown member 'b'")
run("csvdup_t", "struct csvdup_t {\n  int8_t a;  // @csv a b\n  int8_t b;\n}\n", 2, "two CSV columns named b")
run("csvfirst_t", "struct csvfirst_t {\n  // @csvfirst a,zz\n  int8_t a;\n}\n", 2, "@csvfirst names unknown member 'zz'")
run("enumid_t", "struct enumid_t {\n  int8_t n;  // @enum n N_\n  const int8_t N_1 = 0;\n}\n", 2,
    "no distinct C++ enumerators")
run("grouparr_t", "struct grouparr_t {\n  int8_t a[2];  // @group g\n}\n", 2,
    "@group is for scalar numbers and booleans only")
run("groupline_t", "struct groupline_t {\n  // @group g\n  int8_t a;\n}\n", 2, "@group belongs in its member's own line")
run("groupcase_t", "struct groupcase_t {\n  int8_t a;  // @group G\n}\n", 2, "malformed annotation")
run("chan_t", "struct chan_t  // @channel lower\n{\n  int8_t a;\n}\n", 2, "malformed annotation")
run("good_t", "struct good_t  // @channel GOOD\n{\n  // @csvfirst b\n  int8_t a;  // @enum a A_\n"
    "  double b[2];  // @csv b bee 1\n  string k;  // @enum k K_\n"
    "  const int8_t A_X = -1, A_Y = 0, K_ONE = 0, K_TWO = 1;\n"
    "  int64_t n;  // @group my_room counted things\n  boolean up;  // @group my_room\n}\n", 0)
good = open(os.path.join(work, "out_good_t", "src", "codec.cpp")).read()
names = open(os.path.join(work, "out_good_t", "names", "include", "hoist", "msg", "names.hpp")).read()
for what, ok in [('columns bee_1, bee_2, a in that order', good.find('{"bee_1", [') < good.find('{"bee_2", [') < good.find('{"a", [')),
                 ("A_ table starts at -1", "kAFirst = -1" in names and '"X", "Y"' in names),
                 ("K_ table for a string member", '"ONE", "TWO"' in names),
                 ("channel GOOD", '{"hoist.good_t", "GOOD"}' in names),
                 ("enum class A : std::int8_t {X = -1, Y = 0}",
                  "enum class A : std::int8_t {\n  X = -1,\n  Y = 0\n};" in names),
                 ("@group my_room: struct MyRoom {n, up} with fillInto",
                  all(x in open(os.path.join(work, "out_good_t", "include", "hoist", "msg", "groups.hpp")).read()
                      for x in ("struct MyRoom {", "std::int64_t n = 0;  ///< counted things", "bool up = false;",
                                "void fillInto(::hoist::good_t& m) const {", "m.up = up;"))),
                 ("bus::kChannelGood", 'kChannelGood = "GOOD"' in open(os.path.join(
                     work, "out_good_t", "bus", "include", "hoist", "bus", "channels.hpp")).read())]:
    print(f"{'ok  ' if ok else 'FAIL'} good_t: {what}")
    passed, failed = passed + ok, failed + (not ok)
print(f"{passed} passed, {failed} failed")
sys.exit(1 if failed else 0)

#!/usr/bin/env python3
"""lcm_codec_gen.py -- generate the checked decoders, JSON codec, all-finite
checks, CSV writers and name tables of msgs/*.lcm.

Reads the LCM type definitions (package, struct, primitive members, members of
another hoist type (nested structs), fixed and variable-length one-dimensional
arrays of either, strings, consts) and writes

  OUT/include/hoist/msg/codec.hpp   the API (DecodeStatus, checkedDecode, toJson,
                                    fromJson, jsonSchema, TypeInfo, allTypes,
                                    allFinite, csvColumns/csvHeader/csvRow,
                                    allEnums)
  OUT/include/hoist/msg/groups.hpp  one struct per `@group` of a type, with
                                    fillInto(msg)
  OUT/src/codec.cpp                 one byte walker, one JSON converter pair,
                                    one JSON Schema, one all-finite check and
                                    one CSV column table per type
  OUT/names/include/hoist/msg/names.hpp
                                    the name tables and channels alone
                                    (header-only, no LCM or JSON)
  OUT/bus/include/hoist/bus/channels.hpp
                                    the channel names for C++ (kChannel*,
                                    bus::Channels; header-only)
  OUT/js/hoist_msgs.js              the same for the dashboard page (ES module)

The steps live in lcmgen/ (parse.py, fingerprint.py, sizes.py, schema.py,
emit.py); the C++ is in the Jinja2 templates of templates/ (Debian package
python3-jinja2).  docs/codec.md describes the output.

Annotations (comments in the .lcm file; they do not change the LCM semantics
or the fingerprint):
  // @max COUNT N      the variable-length arrays sized by member COUNT hold at
                       most N elements (default 65536); N may also name an
                       integer const of the struct (@max num_points
                       MAX_POINTS).  Without @max, a count member num_<x> takes
                       the struct's const MAX_<X> when there is one (the
                       "MAX_* constant" convention of forecast_t).
  // @maxlen MEMBER N  string MEMBER (or each element of a string array) holds
                       at most N bytes (default 4096)
  // @enum MEMBER PREFIX_
                       the struct's integer consts PREFIX_<NAME> (distinct,
                       consecutive values) name the values of MEMBER (an
                       integer, or a string whose values are the NAMEs):
                       name tables enums::<type>::k<Stem>Names, and the CSV
                       writes MEMBER (an integer) by name
  // @csv MEMBER COLUMN [FIRST]
                       the CSV column of MEMBER is COLUMN (an array's:
                       COLUMN_FIRST, COLUMN_FIRST+1, ...; FIRST default 0)
  // @csvfirst A,B,... these members' CSV columns come first, in this order
  // @channel NAME     the type's LCM channel without the prefix (kChannels,
                       bus::kChannel<Name> and bus::Channels::<name>,
                       CHANNELS of hoist_msgs.js)
  // @group name       (in a scalar member's own line) the member is one of the
                       figures one writer keeps: struct groups::<type>::<Name>
                       with those members and fillInto(msg)

Usage: lcm_codec_gen.py --out DIR FILE.lcm...
       lcm_codec_gen.py --fingerprints FILE.lcm...   (prints name and hash)
"""
import argparse
import os
import sys

sys.dont_write_bytecode = True  # run at build time: no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from lcmgen.emit import generate  # noqa: E402
from lcmgen.fingerprint import M64, fingerprint  # noqa: E402,F401  (fuzz/make_seeds.py uses them)
from lcmgen.model import GenError  # noqa: E402
from lcmgen.parse import load  # noqa: E402,F401
from lcmgen.sizes import max_size, min_size  # noqa: E402


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", help="output directory (include/ and src/ are created in it)")
    ap.add_argument("--fingerprints", action="store_true", help="print each type's fingerprint and exit")
    ap.add_argument("files", nargs="+")
    a = ap.parse_args(argv)
    try:
        structs = load(a.files)
        if a.fingerprints:
            for s in structs:
                print(f"{s.full} 0x{fingerprint(s) & M64:016x} min {min_size(s)} max {max_size(s)}")
            return 0
        if not a.out:
            ap.error("--out DIR is required")
        generate(structs, a.out)
    except GenError as e:
        print(f"lcm_codec_gen.py: {e}", file=sys.stderr)
        return 2
    except OSError as e:
        print(f"lcm_codec_gen.py: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

#!/usr/bin/env python3
"""Reference CSVs from hoist-sim result CSVs (columns t,y_c,theta,lambda_1..4).

  richardson.py run200.csv run400.csv out.csv
      Richardson extrapolation in n (error ~ 1/n) of two runs with n1 = 200,
      n2 = 400:  y_inf = (n2 y2 - n1 y1) / (n2 - n1) = 2 y400 - y200.
      Keeps every 2nd row (0.02 s).  Used for the static start, whose error
      is the static truncation of the point loads (exactly 1/n).
  richardson.py run.csv out.csv
      One run as it is, every row (0.01 s).  Used for the rest start, from
      the corrected model at n = 400 (see generate.sh: from rest the
      uncorrected sleeve forces do not converge as 1/n)."""
import csv
import sys

COLS = ["t", "y_c", "theta", "lambda_1", "lambda_2", "lambda_3", "lambda_4"]


def read(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"{path}: no rows")
    return rows


def write(path, rows):
    with open(path, "w", newline="") as f:
        f.write(",".join(COLS) + "\n")
        for vals in rows:
            f.write("%.2f," % vals[0] + ",".join("%.9e" % v for v in vals[1:]) + "\n")


def main():
    if len(sys.argv) == 3:
        a = read(sys.argv[1])
        write(sys.argv[2], [[float(r[c]) for c in COLS] for r in a])
        return
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    a, b = read(sys.argv[1]), read(sys.argv[2])
    if len(a) != len(b):
        sys.exit("runs differ in length")
    out = []
    for k in range(0, len(a), 2):
        ra, rb = a[k], b[k]
        if abs(float(ra["t"]) - float(rb["t"])) > 1e-9:
            sys.exit(f"time mismatch at row {k}")
        out.append([float(ra["t"])] + [2.0 * float(rb[c]) - float(ra[c]) for c in COLS[1:]])
    write(sys.argv[3], out)


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Richardson extrapolation in n (error ~ 1/n) of two hoist-sim result CSVs:
y_inf = (n2 y2 - n1 y1) / (n2 - n1) with n1 = 200, n2 = 400, i.e. 2 y400 - y200.
Usage: richardson.py run200.csv run400.csv out.csv  (keeps every 2nd row: 0.02 s)."""
import csv
import sys

COLS = ["t", "y_c", "theta", "lambda_1", "lambda_2", "lambda_3", "lambda_4"]


def read(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"{path}: no rows")
    return rows


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    a, b = read(sys.argv[1]), read(sys.argv[2])
    if len(a) != len(b):
        sys.exit("runs differ in length")
    with open(sys.argv[3], "w", newline="") as f:
        f.write(",".join(COLS) + "\n")
        for k in range(0, len(a), 2):
            ra, rb = a[k], b[k]
            if abs(float(ra["t"]) - float(rb["t"])) > 1e-9:
                sys.exit(f"time mismatch at row {k}")
            vals = [float(ra["t"])] + [2.0 * float(rb[c]) - float(ra[c]) for c in COLS[1:]]
            f.write("%.2f," % vals[0] + ",".join("%.9e" % v for v in vals[1:]) + "\n")


if __name__ == "__main__":
    main()

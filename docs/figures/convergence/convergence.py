#!/usr/bin/env python3
"""Errors of the corrected/uncorrected model against the converged references
(tests/data/c1-converged) and the rest-start figure; run by convergence.sh.

  convergence.py RUNDIR OUTDIR

RUNDIR holds hoist-sim CSVs named {static,rest}-N-{on,off}.csv.  Writes
OUTDIR/errors.csv (case, n, correction, nRMS of y_c, theta, lambda_1..4 over
the whole signal, the same after a zero-phase low-pass at the n-th rope mode
f_n on both, and the reference's content above f_n) and OUTDIR/rest.csv (the
series the figure plots)."""
import csv
import math
import os
import sys

COLS = ["y_c", "theta", "lambda_1", "lambda_2", "lambda_3", "lambda_4"]
HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.path.join(HERE, "..", "..", "..", "tests", "data", "c1-converged")


def read(path):
    with open(path, newline="") as f:
        return {round(float(r["t"]) * 100): [float(r[c]) for c in COLS] for r in csv.DictReader(f)}


def top_mode_hz(n, L=400.0, rho2=2.2, Tb=30000.0, g=9.81):
    """WKB estimate of the n-th guide-rope mode: f_n = n / (2 Int dx / c),
    c = sqrt(T / rho2), T = Tb + rho2 g (L - x); within 0.5 % of the model's
    eigenvalue (StaticCorrection.PaperRestStart... prints it)."""
    # Int_0^L dx / sqrt(T/rho2) with T linear in x: closed form
    T0, T1 = Tb + rho2 * g * L, Tb
    tt = 2.0 * (math.sqrt(T0) - math.sqrt(T1)) / (rho2 * g) * math.sqrt(rho2)
    return n / (2.0 * tt)


def butter2(x, fc, dt):
    K = math.tan(math.pi * fc * dt)
    q = math.sqrt(2.0)
    nrm = 1.0 / (1.0 + q * K + K * K)
    b0 = K * K * nrm
    b1, b2 = 2 * b0, b0
    a1, a2 = 2 * (K * K - 1) * nrm, (1 - q * K + K * K) * nrm
    x1 = x2 = y1 = y2 = x[0]
    out = []
    for v in x:
        o = b0 * v + b1 * x1 + b2 * x2 - a1 * y1 - a2 * y2
        x2, x1, y2, y1 = x1, v, y1, o
        out.append(o)
    return out


def low_pass(x, fc, dt):
    """Zero-phase 2nd-order Butterworth forwards and backwards (as the test's
    lowPass): zero before the first sample, held after the last."""
    pad = int(math.ceil(10.0 / (fc * dt)))
    y = [0.0] * pad + list(x) + [x[-1]] * pad
    y = butter2(y, fc, dt)
    y = butter2(y[::-1], fc, dt)[::-1]
    return y[pad:pad + len(x)]


def nrms(a, b):
    return math.sqrt(sum((u - v) ** 2 for u, v in zip(a, b)) / sum(v * v for v in b))


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    rundir, outdir = sys.argv[1], sys.argv[2]
    refs = {"static": read(os.path.join(DATA, "static.csv")), "rest": read(os.path.join(DATA, "rest.csv"))}
    rows = []
    for name in sorted(os.listdir(rundir)):
        parts = name[:-4].split("-")
        if len(parts) != 3 or parts[0] not in refs:
            continue
        case, n, corr = parts[0], int(parts[1]), parts[2]
        run, ref = read(os.path.join(rundir, name)), refs[case]
        keys = sorted(set(run) & set(ref))
        dt = (keys[1] - keys[0]) / 100.0
        fc = top_mode_hz(n)
        raw, band, above = [], [], []
        for c in range(6):
            a = [run[k][c] for k in keys]
            b = [ref[k][c] for k in keys]
            raw.append(nrms(a, b))
            if case == "rest":
                la, lb = low_pass(a, fc, dt), low_pass(b, fc, dt)
                band.append(nrms(la, lb))
                above.append(nrms(lb, b))
        rows.append((case, n, corr, fc, raw, band, above))
    rows.sort(key=lambda r: (r[0], r[2], r[1]))
    with open(os.path.join(outdir, "errors.csv"), "w") as f:
        f.write("case,n,correction,f_n_hz," + ",".join("nrms_" + c for c in COLS) + ","
                + ",".join("band_nrms_" + c for c in COLS) + "," + ",".join("ref_above_f_n_" + c for c in COLS) + "\n")
        for case, n, corr, fc, raw, band, above in rows:
            f.write("%s,%d,%s,%.3f," % (case, n, corr, fc) + ",".join("%.3e" % v for v in raw) + ","
                    + ",".join("%.3e" % v for v in (band or [float("nan")] * 6)) + ","
                    + ",".join("%.3e" % v for v in (above or [float("nan")] * 6)) + "\n")
    print("case    n  corr   f_n[Hz]  y_c      theta    lambda_1 | in band: theta  lambda_1 | ref above f_n: theta lambda_1")
    for case, n, corr, fc, raw, band, above in rows:
        extra = "| %8.2e %8.2e | %8.2e %8.2e" % (band[1], band[2], above[1], above[2]) if band else ""
        print("%-6s %3d  %-4s  %5.2f   %8.2e %8.2e %8.2e %s" % (case, n, corr, fc, raw[0], raw[1], raw[2], extra))
    # The figure's series: rest start, converged, its low-pass at f_20, n = 20 on/off, n = 50 on.
    ref = refs["rest"]
    keys = sorted(ref)
    f20 = top_mode_hz(20)
    series = {"ref": ref}
    for tag in ("20-on", "20-off", "50-on"):
        p = os.path.join(rundir, "rest-%s.csv" % tag)
        if os.path.exists(p):
            series[tag] = read(p)
    lp = {c: low_pass([ref[k][c] for k in keys], f20, 0.01) for c in (1, 2)}
    with open(os.path.join(outdir, "rest.csv"), "w") as f:
        names = list(series)
        f.write("t," + ",".join("theta_%s,lambda_1_%s" % (s, s) for s in names) + ",theta_ref_lp,lambda_1_ref_lp\n")
        for i, k in enumerate(keys):
            if k > 1000:
                break
            f.write("%.2f," % (k / 100.0) + ",".join("%.6e,%.6e" % (series[s][k][1], series[s][k][2]) for s in names)
                    + ",%.6e,%.6e\n" % (lp[1][i], lp[2][i]))


if __name__ == "__main__":
    main()

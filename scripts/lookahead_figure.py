#!/usr/bin/env python3
"""The e-stop forecast's slack-rope margin along the paper trip (see
docs/lookahead.md), as an SVG figure with no plotting library.

Runs `hoist-forecast-table N EVERY` (the model's forecast engine along the
paper's trip on the demo shaft: from the twin's state every EVERY seconds,
an emergency stop at 3 m/s^2 / 10 m/s^3 over a 20-s horizon) and plots, per
forecast start time t0:
  * the slack margin = the smallest lambda_0 the e-stop would cause / the
    static rope force m g + Fa (1 = at rest; 0 = slack rope), and the
    PREDICTED_SLACK threshold (0.5);
  * the largest lambda_0 / static force (the overload side).
Also writes the numbers as CSV next to the figure.

  scripts/lookahead_figure.py [--bin build/bin] [--modes 50] [--every 1]
                              [--out docs/figures/lookahead/estop-slack-margin]
"""
import argparse
import os
import subprocess
import sys

STATIC = 800.0 * 9.81 + 1000.0  # m g + Fa of the paper's shaft [N]
SLACK_FRACTION = 0.5            # [alarms] slack_fraction (default): ROPE_SLACK, PREDICTED_SLACK


def run_table(binary, modes, every):
    out = subprocess.run([binary, str(modes), str(every)], check=True, capture_output=True, text=True).stdout
    rows = []
    for line in out.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) < 4 or not cells[0].replace(".", "").isdigit():
            continue
        t0 = float(cells[0])
        lo, hi = (float(x) for x in cells[2].split("/"))
        rows.append((t0, lo / STATIC, hi / STATIC, lo, hi))
    if not rows:
        sys.exit("no rows from " + binary)
    return rows


def svg(rows, path, modes):
    W, H, L, R, T, B = 720, 400, 70, 20, 40, 60
    xmax = max(r[0] for r in rows)
    ymin, ymax = 0.0, 1.6

    def X(t):
        return L + (W - L - R) * t / xmax

    def Y(v):
        return T + (H - T - B) * (ymax - v) / (ymax - ymin)

    o = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" font-family="sans-serif" font-size="12">',
         f'<rect width="{W}" height="{H}" fill="white"/>',
         f'<text x="{W / 2}" y="20" text-anchor="middle" font-size="14">E-stop forecast along the paper trip '
         f'(demo shaft, n = {modes}, 3 m/s² / 10 m/s³, 20-s horizon)</text>']
    for i in range(0, 9):
        v = ymin + i * 0.2
        o.append(f'<line x1="{L}" y1="{Y(v):.1f}" x2="{W - R}" y2="{Y(v):.1f}" stroke="#ddd"/>')
        o.append(f'<text x="{L - 6}" y="{Y(v) + 4:.1f}" text-anchor="end">{v:.1f}</text>')
    for t in range(0, int(xmax) + 1, 5):
        o.append(f'<line x1="{X(t):.1f}" y1="{T}" x2="{X(t):.1f}" y2="{H - B}" stroke="#eee"/>')
        o.append(f'<text x="{X(t):.1f}" y="{H - B + 16}" text-anchor="middle">{t}</text>')
    o.append(f'<text x="{(L + W - R) / 2}" y="{H - 22}" text-anchor="middle">forecast start t0 along the trip [s]</text>')
    o.append(f'<text x="16" y="{(T + H - B) / 2}" text-anchor="middle" '
             f'transform="rotate(-90 16 {(T + H - B) / 2})">lambda_0 / static force (m g + Fa)</text>')
    o.append(f'<line x1="{L}" y1="{Y(SLACK_FRACTION):.1f}" x2="{W - R}" y2="{Y(SLACK_FRACTION):.1f}" '
             f'stroke="#c00" stroke-dasharray="6,4"/>')
    o.append(f'<text x="{W - R - 4}" y="{Y(SLACK_FRACTION) - 5:.1f}" text-anchor="end" fill="#c00">'
             f'PREDICTED_SLACK threshold ({SLACK_FRACTION})</text>')
    for idx, color, label in ((1, "#06c", "slack margin: min lambda_0 / static"),
                              (2, "#888", "max lambda_0 / static")):
        pts = " ".join(f"{X(r[0]):.1f},{Y(r[idx]):.1f}" for r in rows)
        o.append(f'<polyline points="{pts}" fill="none" stroke="{color}" stroke-width="2"/>')
    o.append(f'<rect x="{L + 10}" y="{T + 8}" width="250" height="40" fill="white" stroke="#ccc"/>')
    o.append(f'<line x1="{L + 18}" y1="{T + 20}" x2="{L + 40}" y2="{T + 20}" stroke="#06c" stroke-width="2"/>')
    o.append(f'<text x="{L + 46}" y="{T + 24}">slack margin: min lambda_0 / static</text>')
    o.append(f'<line x1="{L + 18}" y1="{T + 38}" x2="{L + 40}" y2="{T + 38}" stroke="#888" stroke-width="2"/>')
    o.append(f'<text x="{L + 46}" y="{T + 42}">max lambda_0 / static</text>')
    o.append("</svg>")
    with open(path, "w") as f:
        f.write("\n".join(o) + "\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default="build/bin")
    ap.add_argument("--modes", type=int, default=50)
    ap.add_argument("--every", type=float, default=1.0)
    ap.add_argument("--out", default="docs/figures/lookahead/estop-slack-margin")
    a = ap.parse_args()
    rows = run_table(os.path.join(a.bin, "hoist-forecast-table"), a.modes, a.every)
    os.makedirs(os.path.dirname(a.out), exist_ok=True)
    with open(a.out + ".csv", "w") as f:
        f.write("t0,slack_margin,max_over_static,lambda0_min,lambda0_max\n")
        for r in rows:
            f.write(f"{r[0]:g},{r[1]:.4f},{r[2]:.4f},{r[3]:.0f},{r[4]:.0f}\n")
    svg(rows, a.out + ".svg", a.modes)
    worst = min(rows, key=lambda r: r[1])
    print(f"{len(rows)} forecasts; smallest slack margin {worst[1]:.3f} at t0 = {worst[0]:g} s "
          f"(lambda_0 {worst[3]:.0f} N); wrote {a.out}.svg and .csv")


if __name__ == "__main__":
    main()

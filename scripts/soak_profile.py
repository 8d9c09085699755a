#!/usr/bin/env python3
"""Writes a long hoist profile CSV (t,v,a,l) for scripts/soak.sh: repeated
round trips of the paper's trapezoid (vmax 5 m/s, a 1 m/s^2, 50 m <-> 300 m),
5 s dwell at each end, sampled every `dt` seconds for `duration` seconds.

  soak_profile.py OUT.csv DURATION [DT]
"""
import sys


def trip_state(tau, direction, l_start):
    """Trapezoid trip of 250 m: 5 s accel at 1 m/s^2, 45 s at 5 m/s, 5 s decel."""
    amax, vmax, ta, tc = 1.0, 5.0, 5.0, 45.0
    if tau < ta:
        a, v, s = amax, amax * tau, 0.5 * amax * tau * tau
    elif tau < ta + tc:
        a, v, s = 0.0, vmax, 12.5 + vmax * (tau - ta)
    elif tau < 2 * ta + tc:
        u = tau - ta - tc
        a, v, s = -amax, vmax - amax * u, 237.5 + vmax * u - 0.5 * amax * u * u
    else:
        a, v, s = 0.0, 0.0, 250.0
    return direction * v, direction * a, l_start + direction * s


def main():
    out, duration = sys.argv[1], float(sys.argv[2])
    dt = float(sys.argv[3]) if len(sys.argv) > 3 else 0.01
    n = int(round(duration / dt))
    dwell, trip = 5.0, 55.0
    cycle = 2 * (dwell + trip)
    with open(out, "w") as f:
        f.write("# soak profile: paper trapezoid round trips, 50 m <-> 300 m\n")
        f.write("t,v,a,l\n")
        for k in range(n + 1):
            t = k * dt
            c = t % cycle
            if c < dwell:
                v, a, l = 0.0, 0.0, 50.0
            elif c < dwell + trip:
                v, a, l = trip_state(c - dwell, +1.0, 50.0)
            elif c < 2 * dwell + trip:
                v, a, l = 0.0, 0.0, 300.0
            else:
                v, a, l = trip_state(c - 2 * dwell - trip, -1.0, 300.0)
            f.write("%.2f,%.17g,%.17g,%.17g\n" % (t, v, a, l))
    print(n + 1)


if __name__ == "__main__":
    main()

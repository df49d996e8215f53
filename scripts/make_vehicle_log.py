#!/usr/bin/env python3
"""Writes data/vehicle_logs/yard_loop.csv: a synthetic 130 s drive for
`vehicle.path: log` (docs/formats.md, "Vehicle log") — not a recording.

A car-park loop driven as a driver would: straights at 2.5 m/s, the speed
eased to 1.5 m/s through four 6 m-radius corners (curvature ramped in and out
over 3 m, as a steering wheel turns), and a lane change on the second
straight. The motion is integrated at 1 ms (speed and curvature as the
inputs of a unicycle) and logged at 10 Hz, as a GNSS/INS logger would:
t, x, y, yaw [rad], speed [m/s]. Standard library only.

    python3 scripts/make_vehicle_log.py > data/vehicle_logs/yard_loop.csv
"""
import math

DT, LOG_EVERY, DURATION = 0.001, 100, 130.0
V_STRAIGHT, V_CORNER, ACCEL = 2.5, 1.5, 0.8
R, RAMP = 6.0, 3.0

# The path as (length [m], curvature at its start, at its end), in order.
quarter = math.pi / 2 * R - RAMP  # a corner's arc length at full curvature, beside its two ramps
LANE = [(8.0, 0.0, 0.0), (6.0, 0.0, 0.08), (6.0, 0.08, -0.08), (6.0, -0.08, 0.0)]
CORNER = [(RAMP, 0.0, 1 / R), (quarter, 1 / R, 1 / R), (RAMP, 1 / R, 0.0)]
LOOP = [(30.0, 0.0, 0.0)] + CORNER + [(6.0, 0.0, 0.0)] + LANE + [(4.0, 0.0, 0.0)] + CORNER + \
       [(30.0, 0.0, 0.0)] + CORNER + [(30.0, 0.0, 0.0)] + CORNER


def curvature_at(s):
    s = s % sum(p[0] for p in LOOP)
    for length, k0, k1 in LOOP:
        if s < length:
            return k0 + (k1 - k0) * s / length
        s -= length
    return 0.0


def main():
    x = y = yaw = s = 0.0
    v = V_STRAIGHT
    print("# touchdown synthetic vehicle log (scripts/make_vehicle_log.py): a car-park loop with a lane change")
    print("t,x,y,yaw,speed")
    steps = int(round(DURATION / DT))
    for i in range(steps + 1):
        if i % LOG_EVERY == 0:
            print(f"{i * DT:.1f},{x:.4f},{y:.4f},{yaw:.5f},{v:.3f}")
        # Slow for what is 6 m ahead: a corner's curvature.
        ahead = max(abs(curvature_at(s + d)) for d in (0.0, 2.0, 4.0, 6.0))
        target = V_CORNER if ahead > 0.5 / R else V_STRAIGHT
        v += max(-ACCEL * DT, min(ACCEL * DT, target - v))
        k = curvature_at(s)
        yaw += v * k * DT
        x += v * math.cos(yaw) * DT
        y += v * math.sin(yaw) * DT
        s += v * DT


if __name__ == "__main__":
    main()

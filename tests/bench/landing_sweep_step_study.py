#!/usr/bin/env python3
"""Step-size study of the landing sweep (issue 35): every bundled terrain's
default sweep (20 headings x 10 runs, seed 1, 2 threads) at physics steps of
1, 2, 3 and 4 ms. For each step and terrain it prints the chosen heading,
whether the safe/unsafe verdicts per heading equal those at 2 ms (the
default) and at 1 ms (the finest), the median and largest change of S per
heading against the 1 ms sweep, and the median simulated-to-wall ratio of
one landing.

Usage: tests/bench/landing_sweep_step_study.py [build-dir]
"""
import json
import pathlib
import statistics
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
BUILD = pathlib.Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "build"
STEPS = ["0.001", "0.002", "0.003", "0.004"]
CASES = [("flat", 0.0), ("incline", 0.0), ("plateau", 0.0), ("post", 0.0), ("rubble", 0.0),
         ("slope_gentle", 0.0), ("slope_steep", 0.0), ("step", 0.0), ("step", 0.12)]


def sweep(terrain, x, step):
    out = subprocess.run([str(BUILD / "apps" / "landing_sweep"), str(ROOT / f"data/terrains/{terrain}.pcd"),
                          "--extrinsics", str(ROOT / f"data/terrains/{terrain}.extrinsics.yaml"),
                          "--landing-point", f"{x},0", "--threads", "2", "--step", step, "--json"],
                         check=True, capture_output=True, text=True).stdout
    return json.loads(out)


def verdicts(d):
    return [h["safe"] for h in d["headings"]]


def main():
    print("terrain        step   best  verdicts=2ms verdicts=1ms  median|dS| max|dS| (vs 1 ms)  one run x real time")
    for terrain, x in CASES:
        runs = {step: sweep(terrain, x, step) for step in STEPS}
        fine, default = runs["0.001"], runs["0.002"]
        name = terrain + (f"@{x:g}" if x else "")
        for step in STEPS:
            d = runs[step]
            ds = [abs(a["score_rad"] - b["score_rad"]) for a, b in zip(d["headings"], fine["headings"])
                  if a["score_rad"] is not None and b["score_rad"] is not None]
            print(f"{name:14s} {float(step) * 1000:3.0f} ms {d['best']['yaw_deg']:5.0f}  "
                  f"{'yes' if verdicts(d) == verdicts(default) else 'NO':>12s} "
                  f"{'yes' if verdicts(d) == verdicts(fine) else 'NO':>12s}  "
                  f"{statistics.median(ds):10.4f} {max(ds):7.4f}            {d['run_simulated_to_wall']:6.0f}")


if __name__ == "__main__":
    main()

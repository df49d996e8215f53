#!/usr/bin/env python3
"""Issue 57: the landing sweep's decision mode against the full sweep on
random terrains of terrain_synth (slopes, steps up and down, plateaus and
pits, rubble, posts), one per seed. For each: the decision (land or not),
the chosen heading and its S must be the full sweep's exactly; prints the
landings and the sweep time of both and the median speed-up.

    tests/bench/sweep_decision_terrains.py --build build --seeds 1-50 --threads 2

Standard library only. Exit 1 if any decision differs.
"""
import argparse
import json
import os
import random
import statistics
import subprocess
import sys
import tempfile


def terrain_args(seed):
    """A random terrain_synth command for this seed (deterministic)."""
    rng = random.Random(seed)
    kind = rng.choice(["incline", "step", "plateau", "rubble", "post"])
    args = [kind, "--seed", str(seed), "--camera-yaw", f"{rng.uniform(0, 360):.1f}"]
    if kind == "incline":
        args += ["--slope", f"{rng.uniform(0, 35):.1f}", "--azimuth", f"{rng.uniform(0, 360):.1f}"]
    elif kind == "step":
        args += ["--step-height", f"{rng.choice([-1, 1]) * rng.uniform(0.03, 0.25):.3f}",
                 "--edge-offset", f"{rng.uniform(-0.3, 0.3):.3f}", "--azimuth", f"{rng.uniform(0, 360):.1f}"]
    elif kind == "plateau":
        args += ["--plateau-height", f"{rng.choice([-1, 1]) * rng.uniform(0.03, 0.2):.3f}",
                 "--plateau-size", f"{rng.uniform(0.2, 0.9):.2f}", f"{rng.uniform(0.2, 0.9):.2f}"]
    elif kind == "rubble":
        args += ["--rubble-count", str(rng.randint(10, 120)), "--rubble-height", f"{rng.uniform(0.02, 0.12):.3f}"]
    else:
        args += ["--post", f"{rng.uniform(-0.3, 0.3):.3f}", f"{rng.uniform(-0.3, 0.3):.3f}",
                 f"{rng.uniform(0.02, 0.06):.3f}", f"{rng.uniform(0.05, 0.4):.3f}"]
    return args


def sweep(build, cloud, extrinsics, threads, full):
    cmd = [os.path.join(build, "apps/landing_sweep"), cloud, "--extrinsics", extrinsics, "--threads", str(threads),
           "--json"] + (["--full"] if full else [])
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    return json.loads(out)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--build", default="build")
    p.add_argument("--seeds", default="1-50", help="first-last")
    p.add_argument("--threads", type=int, default=2)
    a = p.parse_args()
    first, last = (int(x) for x in a.seeds.split("-"))
    same = 0
    speedups, shares = [], []
    print("| seed | terrain | land | heading [deg] | S [rad] | landings decide / full | sweep [s] decide / full |")
    print("|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for seed in range(first, last + 1):
            cloud = os.path.join(tmp, f"t{seed}.pcd")
            extr = os.path.join(tmp, f"t{seed}.yaml")
            args = terrain_args(seed)
            subprocess.run([os.path.join(a.build, "apps/terrain_synth")] + args +
                           ["-o", cloud, "--extrinsics-out", extr], check=True, capture_output=True)
            d = sweep(a.build, cloud, extr, a.threads, False)
            f = sweep(a.build, cloud, extr, a.threads, True)
            equal = d["land"] == f["land"] and d["best"] == f["best"]
            same += equal
            speedups.append(f["seconds"] / d["seconds"])
            shares.append(d["runs"] / f["runs"])
            best = f["best"] or {}
            print(f"| {seed} | {' '.join(args[:1] + args[3:])} | {'yes' if f['land'] else 'no'} | "
                  f"{best.get('yaw_deg', '-')} | {best.get('score_rad', '-')} | {d['runs']} / {f['runs']} | "
                  f"{d['seconds']:.3f} / {f['seconds']:.3f} |" + ("" if equal else " **DIFFERS**"), flush=True)
    n = last - first + 1
    print(f"\nsame decision, heading and S: {same} of {n}; landings flown: median {statistics.median(shares):.2f} "
          f"of the full sweep's; speed-up of the sweep: median {statistics.median(speedups):.2f}x "
          f"(min {min(speedups):.2f}, max {max(speedups):.2f})")
    return 0 if same == n else 1


if __name__ == "__main__":
    sys.exit(main())

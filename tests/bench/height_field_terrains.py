#!/usr/bin/env python3
"""Issue 57, item 3: the height-field contact against the trimesh contact on
random terrains of terrain_synth (the terrains of sweep_decision_terrains.py,
one per seed), full sweeps. For each terrain: the verdict (land or not), the
chosen heading, the headings whose verdict flips, and one landing's speed
(median simulated/wall) of both. The noise of the runs as the yardstick: the
same comparison between the trimesh with sweep seed 1 and with seed 2.

    tests/bench/height_field_terrains.py --build build --seeds 1-50 --threads 2

Standard library only. Exit 1 if a verdict differs where the seed alone
does not change it.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from sweep_decision_terrains import terrain_args  # noqa: E402  (the same terrains)


def sweep(build, cloud, extrinsics, threads, contact, seed):
    cmd = [os.path.join(build, "apps/landing_sweep"), cloud, "--extrinsics", extrinsics, "--threads", str(threads),
           "--full", "--json", "--contact", contact, "--seed", str(seed)]
    return json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout)


def safe_set(d):
    return {h["yaw_deg"] for h in d["headings"] if h.get("safe")}


def heading(d):
    return d["best"]["yaw_deg"] if d["best"] and d["land"] else None


def flips(a, b):
    """Headings safe in a and not in b, and the other way."""
    sa, sb = safe_set(a), safe_set(b)
    return len(sa - sb), len(sb - sa)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--build", default="build")
    p.add_argument("--seeds", default="1-50", help="first-last")
    p.add_argument("--threads", type=int, default=2)
    a = p.parse_args()
    first, last = (int(x) for x in a.seeds.split("-"))
    rows = []
    print("| seed | terrain | contact | land trimesh / height field / trimesh seed 2 | heading [deg] (same) | "
          "flips safe→unsafe, unsafe→safe: height field / seed 2 | one landing × trimesh / height field |")
    print("|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for seed in range(first, last + 1):
            cloud, extr = os.path.join(tmp, f"t{seed}.pcd"), os.path.join(tmp, f"t{seed}.yaml")
            args = terrain_args(seed)
            subprocess.run([os.path.join(a.build, "apps/terrain_synth")] + args +
                           ["-o", cloud, "--extrinsics-out", extr], check=True, capture_output=True)
            m = sweep(a.build, cloud, extr, a.threads, "trimesh", 1)
            g = sweep(a.build, cloud, extr, a.threads, "height-field", 1)
            n = sweep(a.build, cloud, extr, a.threads, "trimesh", 2)
            r = {"seed": seed, "contact": g["contact"], "verdict": m["land"] == g["land"],
                 "verdict_noise": m["land"] == n["land"], "heading": heading(m) == heading(g),
                 "heading_noise": heading(m) == heading(n), "flips": flips(m, g), "flips_noise": flips(m, n),
                 "speed": (m["run_simulated_to_wall"], g["run_simulated_to_wall"])}
            rows.append(r)
            print(f"| {seed} | {' '.join(args[:1] + args[3:])} | {g['contact']} | "
                  f"{'yes' if m['land'] else 'no'} / {'yes' if g['land'] else 'no'} / {'yes' if n['land'] else 'no'} | "
                  f"{heading(m)} / {heading(g)} ({'yes' if r['heading'] else 'no'}) | "
                  f"{r['flips'][0]}, {r['flips'][1]} / {r['flips_noise'][0]}, {r['flips_noise'][1]} | "
                  f"{r['speed'][0]:.0f} / {r['speed'][1]:.0f} |", flush=True)
    count = len(rows)
    grid = sum(r["contact"] == "height-field" for r in rows)
    verdict = sum(r["verdict"] for r in rows)
    verdict_noise = sum(r["verdict_noise"] for r in rows)
    bad = [r["seed"] for r in rows if not r["verdict"] and r["verdict_noise"]]
    ratios = [r["speed"][1] / r["speed"][0] for r in rows]
    f = [sum(r["flips"][k] for r in rows) for k in (0, 1)]
    fn = [sum(r["flips_noise"][k] for r in rows) for k in (0, 1)]
    print(f"\nheight field detected on {grid} of {count}; same verdict: height field {verdict} of {count}, "
          f"seed 2 {verdict_noise} of {count}; same heading: height field {sum(r['heading'] for r in rows)}, "
          f"seed 2 {sum(r['heading_noise'] for r in rows)}; headings flipped safe→unsafe / unsafe→safe: "
          f"height field {f[0]} / {f[1]}, seed 2 {fn[0]} / {fn[1]} (of {20 * count}); one landing "
          f"height field / trimesh: median {statistics.median(ratios):.2f}x (min {min(ratios):.2f}, "
          f"max {max(ratios):.2f})" + (f"; verdict differs beyond the seed's noise: seeds {bad}" if bad else ""))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())

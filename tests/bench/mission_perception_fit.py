#!/usr/bin/env python3
"""Fit the landing mission's `model` perception to what led_pose achieves on
the independent renderer's sequences (issue 34; docs/benchmarks.md, "Landing
mission", "The perception model's fit").

Reads a work directory of tests/bench/led_independent.py (its sequences'
ground_truth.jsonl and led_pose's per-frame JSON Lines of one mode) and fits,
over the range r from the camera:

  per-axis position error  sigma(r) = sigma_a + sigma_b * r^2   (least squares on the RMS per band)
  no pose (any reason)     p(r)     = dropout + dropout_b * r^2
  per-sequence bias        bias_sigma = RMS of the sequences' mean errors

and prints the figures, a table per range band and the YAML lines for the
mission file's `perception:` section.

    /usr/bin/python3 tests/bench/mission_perception_fit.py --work /tmp/led_independent --mode attitude
"""
import argparse
import glob
import json
import math
import os
import sys

import numpy as np


def read_jsonl(path):
    with open(path) as f:
        return [json.loads(line) for line in f if line.strip()]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--work", required=True, help="led_independent.py's --work directory")
    ap.add_argument("--mode", default="attitude", help="led_pose mode to fit (single, attitude, fuse)")
    ap.add_argument("--bands", default="0.4,0.7,1,1.5,2,2.5,3", help="range band edges [m]")
    a = ap.parse_args()
    edges = [float(x) for x in a.bands.split(",")]
    ranges, errors, ok = [], [], []
    means = []
    runs = sorted(glob.glob(os.path.join(a.work, "led_pose", "*", "*", a.mode + ".jsonl")))
    if not runs:
        sys.exit(f"mission_perception_fit.py: no {a.mode}.jsonl under {a.work}/led_pose (run led_independent.py first)")
    for run in runs:
        constellation, sequence = run.split(os.sep)[-3], run.split(os.sep)[-2]
        truth_path = os.path.join(a.work, "sequences", constellation, sequence, "ground_truth.jsonl")
        truth = {r["frame"]: np.array(r["t"]) for r in read_jsonl(truth_path)}
        seq_err = []
        for r in read_jsonl(run):
            t = truth.get(r["frame"])
            if t is None:
                continue
            rng = float(np.linalg.norm(t))
            ranges.append(rng)
            good = bool(r.get("ok"))
            ok.append(good)
            if good:
                e = np.array(r["t"]) - t
                errors.append((rng, e))
                seq_err.append(e)
        if seq_err:
            means.append(np.mean(seq_err, axis=0))
    ranges = np.array(ranges)
    ok = np.array(ok)
    # Per band: RMS per axis of the errors (outliers beyond 0.1 m, wrong
    # poses, are kept: the model must carry them in its sigma).
    rows = []
    for lo, hi in zip(edges[:-1], edges[1:]):
        e = np.array([err for rng, err in errors if lo <= rng < hi])
        sel = (ranges >= lo) & (ranges < hi)
        if len(e) == 0 or not sel.any():
            continue
        rms = math.sqrt(float(np.mean(e ** 2)))
        rows.append((lo, hi, 0.5 * (lo + hi), int(sel.sum()), 1 - float(ok[sel].mean()), rms,
                     float(np.percentile(np.linalg.norm(e, axis=1), 95))))
    mid = np.array([r[2] for r in rows])
    A = np.vstack([np.ones_like(mid), mid ** 2]).T
    sigma_a, sigma_b = np.linalg.lstsq(A, np.array([r[5] for r in rows]), rcond=None)[0]
    drop_a, drop_b = np.linalg.lstsq(A, np.array([r[4] for r in rows]), rcond=None)[0]
    sigma_a, drop_a = max(sigma_a, 0.0), max(drop_a, 0.0)
    bias = math.sqrt(float(np.mean(np.array(means) ** 2))) if means else 0.0
    print(f"led_pose mode '{a.mode}' on {len(runs)} sequences, {len(ranges)} frames ({int(ok.sum())} with a pose)")
    print()
    print("| range [m] | frames | no pose | per-axis RMS error [m] | model sigma [m] | 95th pct. error [m] | model no pose |")
    print("|---|---|---|---|---|---|---|")
    for lo, hi, m, n, drop, rms, p95 in rows:
        print(f"| {lo:g}-{hi:g} | {n} | {drop:.3f} | {rms:.4f} | {sigma_a + sigma_b * m * m:.4f} | {p95:.4f} | "
              f"{drop_a + drop_b * m * m:.3f} |")
    print()
    print("perception:")
    print(f"  sigma_a: {sigma_a:.4f}")
    print(f"  sigma_b: {sigma_b:.4f}")
    print(f"  bias_sigma: {bias:.4f}")
    print(f"  dropout: {drop_a:.3f}")
    print(f"  dropout_b: {drop_b:.4f}")


if __name__ == "__main__":
    main()

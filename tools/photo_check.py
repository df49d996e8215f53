#!/usr/bin/python3
"""Checks a marker detector on photographs it never saw, with and without its marker.

    /usr/bin/python3 tools/photo_check.py --bin build/apps --out DIR \
        [--detector learned] [--marker 4X4_50:0] [--seed 1] PHOTO...

1. Runs `landing_scenario detect --json` on every photograph as it is: a
   detection at or above --threshold there is confidently wrong (the
   photographs must not show the marker; Debian's opencv-doc images do not
   show 4X4_50 id 0).
2. Prints the marker (with a white margin of one cell) into a copy of each
   photograph under a random perspective, size and grey levels, and runs
   the detector on the copies: recall is the share of copies with a
   detection of IoU >= 0.5 on the printed marker at or above --threshold;
   a detection elsewhere at or above --threshold is confidently wrong.
Only detections of the marker's id count (ArUco reports every id it reads).

The copies are a real background with a drawn marker, not a photograph of a
printed one: no lens blur of the marker's own, no paper curl. They test
what the world cannot: backgrounds the detector never saw. Writes
DIR/copies/*.png, DIR/labels.json, DIR/originals.jsonl, DIR/copies.jsonl and
DIR/summary.json; prints the summary. Needs python3-opencv and numpy only.
"""
import argparse
import json
import math
import os
import subprocess
import sys

import cv2
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from detector_metrics import box_iou  # noqa: E402


def marker_image(dictionary, marker_id, px_per_cell=16):
    d = cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, "DICT_" + dictionary))
    cells = d.markerSize + 2
    img = cv2.aruco.drawMarker(d, marker_id, cells * px_per_cell)
    m = px_per_cell
    return cv2.copyMakeBorder(img, m, m, m, m, cv2.BORDER_CONSTANT, value=255), m


def print_marker(rng, photo, marker, margin):
    """Draws `marker` into `photo` (BGR, in place); returns the black
    border's four corners in the photo [px]."""
    h, w = photo.shape[:2]
    side = rng.uniform(0.06, 0.35) * min(h, w)
    cx, cy = rng.uniform(side, w - side), rng.uniform(side, h - side)
    a = rng.uniform(0, 2 * math.pi)
    rot = np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
    s = marker.shape[0]
    unit = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], float) * 0.5 * side
    dst = unit @ rot.T + [cx, cy] + rng.normal(0, 0.05 * side, (4, 2))  # a mild perspective
    src = np.float32([[0, 0], [s, 0], [s, s], [0, s]])
    M = cv2.getPerspectiveTransform(src, dst.astype(np.float32))
    warped = cv2.warpPerspective(marker.astype(np.float32), M, (w, h), flags=cv2.INTER_AREA)
    alpha = cv2.warpPerspective(np.ones_like(marker, np.float32), M, (w, h), flags=cv2.INTER_LINEAR)
    black, white = rng.uniform(10, 70), rng.uniform(170, 250)
    shade = black + warped / 255 * (white - black)
    grey = photo.astype(np.float32)
    photo[:] = np.clip(grey * (1 - alpha[..., None]) + shade[..., None] * alpha[..., None], 0, 255).astype(np.uint8)
    inner = np.float32([[margin, margin], [s - margin, margin], [s - margin, s - margin], [margin, s - margin]])
    return cv2.perspectiveTransform(inner[None], M)[0]


def detect(binary, detector, images, out):
    with open(out, "w") as f:
        r = subprocess.run([binary, "detect", "--detector", detector, "--json", *images], stdout=f)
    if r.returncode != 0:
        sys.exit(f"photo_check: {binary} detect exited with {r.returncode}")
    return [json.loads(line) for line in open(out)]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("photos", nargs="+")
    ap.add_argument("--bin", default="build/apps", help="directory holding landing_scenario")
    ap.add_argument("--out", required=True)
    ap.add_argument("--detector", default="learned")
    ap.add_argument("--marker", default="4X4_50:0")
    ap.add_argument("--threshold", type=float, default=0.7)
    ap.add_argument("--seed", type=int, default=1)
    a = ap.parse_args()
    binary = os.path.join(a.bin, "landing_scenario")
    dictionary, marker_id = a.marker.split(":")
    marker, margin = marker_image(dictionary, int(marker_id))
    rng = np.random.default_rng(a.seed)
    os.makedirs(os.path.join(a.out, "copies"), exist_ok=True)

    target = int(marker_id)

    def confident(res):  # detections of the target's id (ArUco also reports other ids it reads)
        return [d for d in res["detections"] if d["confidence"] >= a.threshold and d.get("id", target) == target]

    originals = detect(binary, a.detector, a.photos, os.path.join(a.out, "originals.jsonl"))
    wrong_originals = [o["image"] for o in originals if confident(o)]

    labels, copies = [], []
    for i, path in enumerate(a.photos):
        photo = cv2.imread(path, cv2.IMREAD_COLOR)
        if photo is None:
            sys.exit(f"photo_check: {path}: not an image")
        corners = print_marker(rng, photo, marker, margin)
        name = os.path.join(a.out, "copies", f"{i:03d}.png")
        cv2.imwrite(name, photo)
        box = [float(v) for v in (*corners.min(axis=0), *corners.max(axis=0))]
        labels.append({"image": name, "photo": path, "corners": corners.tolist(), "box": box})
        copies.append(name)
    json.dump(labels, open(os.path.join(a.out, "labels.json"), "w"), indent=1)
    found = detect(binary, a.detector, copies, os.path.join(a.out, "copies.jsonl"))
    hits, wrong_copies, sides = 0, [], []
    for lab, res in zip(labels, found):
        gt = np.array(lab["box"])
        sure = confident(res)
        hit = any(box_iou(d["box"], gt) >= 0.5 for d in sure)
        hits += hit
        sides.append((float(np.min(gt[2:] - gt[:2])), hit))
        if any(box_iou(d["box"], gt) < 0.5 for d in sure):
            wrong_copies.append(lab["photo"])
    small = [h for s, h in sides if s < 60]
    summary = {
        "detector": a.detector, "marker": a.marker, "threshold": a.threshold, "photos": len(a.photos),
        "originals_confidently_wrong": len(wrong_originals), "originals_wrong": [os.path.basename(w) for w in wrong_originals],
        "copies_recall": round(hits / len(labels), 3),
        "copies_recall_below_60px": round(sum(small) / max(1, len(small)), 3) if small else None,
        "copies_with_a_confident_box_elsewhere": len(wrong_copies),
        "median_ms": float(np.median([o["ms"] for o in originals + found])),
    }
    json.dump(summary, open(os.path.join(a.out, "summary.json"), "w"), indent=1)
    print(json.dumps(summary, indent=1))


if __name__ == "__main__":
    main()

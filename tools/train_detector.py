#!/usr/bin/python3
"""Trains touchdown's learned marker detector on a `landing_scenario dataset`.

    landing_scenario dataset --out DS --count 12000 --seed 1
    /usr/bin/python3 tools/train_detector.py DS --out data/models/marker-4x4_50-0.onnx

Writes the ONNX model (opset 11, what OpenCV 4.6's DNN module reads), its
manifest beside it (the same name with .json: the marker, the input and
output layout, the dataset, the training configuration, the validation
metrics and the model's sha256; docs/formats.md, "Detector model") and,
with --vectors DIR, stored frames and PyTorch's outputs for the C++
cross-check (tests/scenario/learned_detector_test.cpp).

A training-time tool: it needs python3-torch, python3-onnx and
python3-opencv from Debian (CPU only); building and testing touchdown does
not. Deterministic for a seed on one machine and thread count (torch's CPU
kernels, numpy's generator, no worker processes); see docs/formats.md for
what is and is not bit-exact across machines.

The network, losses and decoding follow CenterNet (Zhou, Wang and
Krähenbühl, "Objects as Points", 2019): a Gaussian peak at the target's
centre on a stride-8 grid trained with the penalty-reduced focal loss, L1
on the centre offset and on the corners at the peak cell.
"""
import argparse
import hashlib
import json
import math
import os
import sys
import time

import cv2
import numpy as np
import torch

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from detector_metrics import average_precision, box_iou  # noqa: E402
from detector_model import CHANNELS, CORNER_SCALE, STRIDE, MarkerNet, export_onnx  # noqa: E402

INPUT_W, INPUT_H = 640, 480
CROP_W, CROP_H = 256, 192  # training crops (multiples of 32: the network's deepest stride); --crop
PAD_VALUE = 0.5


# ---- labels --------------------------------------------------------------------------------

def min_side(corners):
    c = np.asarray(corners, float)
    return min(np.linalg.norm(c[i] - c[(i + 1) % 4]) for i in range(4))


def target_role(row):
    """'positive', 'ignore' or 'none' for a frame's target label.

    Positive: mostly inside the image and unhidden, at least 8 px a side, and
    readable by the world's oracle (observable, or failing only on size,
    angle, noise or the margin leaving the view), or in haze whose contrast
    is still 8 grey levels. Markers a camera could not show (under snow or
    leaves, faded to grey, behind an object) are ignored: the network is
    neither taught to find them nor punished for it. The oracle stops at
    "out-of-view" when the white margin leaves the image, before reading
    contrast or cover: then the weather decides (no ground cover, thin haze)."""
    t, w = row["target"], row["conditions"]
    if not t["in_view"] or not t["corners"]:
        return "none"
    if t["visible_fraction"] < 0.3:
        return "none"
    side = min_side(t["corners"])
    sight = t["sight"]
    clear = max(w["ground_snow"], w["ground_leaves"]) < 0.3 and w["fog"] < 0.15
    readable = sight in ("observable", "noisy", "oblique", "too-small") or (
        sight == "low-contrast" and t["contrast"] >= 8) or (sight == "out-of-view" and clear)
    if (t["inside_fraction"] >= 0.85 and t["visible_fraction"] >= 0.6 and side >= 8 and readable):
        return "positive"
    return "ignore"


def load(dataset, splits):
    rows = []
    with open(os.path.join(dataset, "labels.jsonl")) as f:
        for line in f:
            r = json.loads(line)
            if r["split"] in splits:
                rows.append(r)
    images = np.empty((len(rows), INPUT_H, INPUT_W), np.uint8)
    for i, r in enumerate(rows):
        im = cv2.imread(os.path.join(dataset, r["image"]), cv2.IMREAD_GRAYSCALE)
        if im is None or im.shape != (INPUT_H, INPUT_W):
            sys.exit(f"train_detector: {dataset}/{r['image']}: not a {INPUT_W}x{INPUT_H} grey image")
        images[i] = im
    return rows, images


# ---- targets -------------------------------------------------------------------------------

def sort_corners(c):
    """Clockwise on the screen (y down), from the corner nearest the top-left."""
    c = np.asarray(c, float)
    area2 = sum(c[i, 0] * c[(i + 1) % 4, 1] - c[(i + 1) % 4, 0] * c[i, 1] for i in range(4))
    if area2 < 0:
        c = c[[0, 3, 2, 1]]
    first = int(np.argmin(c.sum(axis=1)))
    return np.roll(c, -first, axis=0)


def make_targets(h, w, targets):
    """Heatmap, regression targets and masks for one sample of h x w input
    pixels; `targets` is a list of (corners [4x2 px], role)."""
    gh, gw = h // STRIDE, w // STRIDE
    heat = np.zeros((gh, gw), np.float32)
    weight = np.ones((gh, gw), np.float32)  # 0: ignored cells
    reg = np.zeros((CHANNELS - 1, gh, gw), np.float32)
    reg_mask = np.zeros((gh, gw), np.float32)
    ys, xs = np.mgrid[0:gh, 0:gw]
    for corners, role in targets:
        c = corners.mean(axis=0) / STRIDE
        side = min_side(corners) / STRIDE
        sigma = max(0.7, side / 6)
        if not (0 <= c[0] < gw and 0 <= c[1] < gh):
            continue
        if role == "ignore":
            r = 2 * sigma + 1
            weight[(xs - c[0]) ** 2 + (ys - c[1]) ** 2 <= r * r] = 0
            continue
        q, p = int(c[0]), int(c[1])
        g = np.exp(-((xs - q) ** 2 + (ys - p) ** 2) / (2 * sigma * sigma)).astype(np.float32)
        heat = np.maximum(heat, g)
        heat[p, q] = 1.0
        reg[0, p, q] = c[0] - q
        reg[1, p, q] = c[1] - p
        rel = (corners - c * STRIDE) / CORNER_SCALE
        reg[2:, p, q] = rel.reshape(-1)
        # Errors relative to the marker's size: a large marker close below
        # would otherwise outweigh every small one.
        reg_mask[p, q] = min(1.0, CORNER_SCALE / max(side * STRIDE, 1.0))
    return heat, weight, reg, reg_mask


# ---- augmentation --------------------------------------------------------------------------

def code_cell_px(row, cells):
    """The smallest code cell [px] of the frame's marker-like squares (the
    target and the distractors in view), or None: the size at which the
    target and a look-alike still differ."""
    sides = [min_side(m["corners"]) for m in [row["target"]] + row.get("distractors", [])
             if m.get("in_view") and m.get("corners")]
    return min(sides) / cells if sides else None


def augment(rng, image, row, role, negatives=None, cells=6):
    """A training crop of CROP_W x CROP_H: scale jitter, a crop (usually
    around the target), a quarter turn, hard negatives pasted (half the
    crops), exposure, blur, noise, JPEG.

    Scale-aware (model v3): the shrink, blur and JPEG never take a code
    cell of the frame's markers below what still tells the target from a
    look-alike (3.5 px a cell, blur sigma <= cell / 4, JPEG only above 8 px
    a cell). v2 blurred a far marker's code away and still taught "this is
    the target" and, beside it, "that look-alike is not": it learned that a
    far marker is a coin toss (0.5-0.6 for both, docs/journal)."""
    target = row["target"]
    cell = code_cell_px(row, cells)
    k = int(rng.integers(0, 4))  # quarter turns (a turned marker is still the marker)
    ow, oh = (CROP_W, CROP_H) if k % 2 == 0 else (CROP_H, CROP_W)  # landscape after the turns
    s_min = 0.7 if cell is None else min(1.0, max(0.7, 3.5 / cell))
    s = rng.uniform(s_min, 1.3)
    if cell is not None:
        cell *= s
    sw, sh = ow / s, oh / s
    if role != "none" and rng.random() < 0.7:
        c = np.asarray(target["corners"], float).mean(axis=0)
        x0 = c[0] - rng.uniform(0.1, 0.9) * sw
        y0 = c[1] - rng.uniform(0.1, 0.9) * sh
    else:
        x0 = rng.uniform(-0.1 * sw, INPUT_W - 0.9 * sw)
        y0 = rng.uniform(-0.1 * sh, INPUT_H - 0.9 * sh)
    # Crop and scale in one affine warp (outside the frame: the pad grey).
    A = np.array([[s, 0, -x0 * s], [0, s, -y0 * s]], np.float64)
    out = cv2.warpAffine(image, A, (ow, oh), flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT,
                         borderValue=int(255 * PAD_VALUE))
    corners = None
    if target["corners"]:
        c = np.asarray(target["corners"], float)
        corners = c @ A[:, :2].T + A[:, 2]
    width = ow
    for _ in range(k):  # np.rot90 turns counter-clockwise: (x, y) -> (y, width - x)
        out = np.rot90(out)
        if corners is not None:
            corners = np.stack([corners[:, 1], width - corners[:, 0]], axis=1)
        width = out.shape[1]
    out = np.ascontiguousarray(out)
    assert out.shape == (CROP_H, CROP_W)
    if negatives is not None and rng.random() < 0.5:
        keep_out = None
        if corners is not None:
            keep_out = (corners.min(axis=0) - 4, corners.max(axis=0) + 4)
        negatives.paste(rng, out, keep_out)
    img = out.astype(np.float32)
    gain, gamma = rng.uniform(0.6, 1.4), rng.uniform(0.7, 1.4)
    img = 255 * np.clip((img / 255) ** gamma * gain + rng.uniform(-0.1, 0.1), 0, 1)
    max_blur = 1.6 if cell is None else min(1.6, cell / 4)
    if rng.random() < 0.3 and max_blur > 0.5:
        img = cv2.GaussianBlur(img, (0, 0), rng.uniform(0.5, max_blur))
    if rng.random() < 0.5:
        img = img + rng.normal(0, rng.uniform(1, 10), img.shape)
    img = np.clip(img, 0, 255).astype(np.uint8)
    if rng.random() < 0.3 and (cell is None or cell >= 8):
        ok, enc = cv2.imencode(".jpg", img, [cv2.IMWRITE_JPEG_QUALITY, int(rng.integers(25, 90))])
        img = cv2.imdecode(enc, cv2.IMREAD_GRAYSCALE)
    targets = []
    if corners is not None and role != "none":
        targets.append((sort_corners(corners), role))
    return img, targets


# ---- hard negatives ------------------------------------------------------------------------
# Things the world never renders but a camera meets, pasted into training
# crops as background: calibration chessboards (v1 scored them up to 0.98),
# markers of other dictionaries and ids, random bit grids, a black square
# in a white ring with no code, and bars like print or windows. Model v1 on
# real photographs showed why (docs/journal/2026-11-29-learned-detector-v1.md).

ARUCO_DICTS = ("DICT_4X4_50", "DICT_5X5_100", "DICT_6X6_250", "DICT_7X7_50", "DICT_ARUCO_ORIGINAL",
               "DICT_APRILTAG_16h5", "DICT_APRILTAG_36h11")


class HardNegatives:
    def __init__(self, marker, round_share=0.0):
        """`round_share`: the share of patches that are round shapes (see
        `round_patch`); 0 draws exactly what models v1-v5's heat maps were
        trained on (no random draw is spent on the choice)."""
        self.round_share = round_share
        self.dict_name = "DICT_" + marker["dictionary"]
        self.target_id = int(marker["id"])
        d = cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, self.dict_name))
        self.bits = d.markerSize
        cells = cv2.aruco.drawMarker(d, self.target_id, self.bits + 2)  # one pixel per cell
        code = (cells[1:-1, 1:-1] > 127)
        self.target_codes = [np.rot90(code, k).copy() for k in range(4)]
        self.dicts = {n: cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, n)) for n in ARUCO_DICTS}

    def _with_margin(self, cells, rng):
        """A cell image (0/255) scaled up, with a white margin of 0-1.5 cells."""
        n = cells.shape[0]
        px = 8
        img = cv2.resize(cells, (cells.shape[1] * px, n * px), interpolation=cv2.INTER_NEAREST)
        m = int(rng.uniform(0, 1.5) * px)
        return cv2.copyMakeBorder(img, m, m, m, m, cv2.BORDER_CONSTANT, value=255)

    def round_patch(self, rng):
        """Round things a square detector may take for a marker: one or two
        dark discs or ellipses (eyes, wheels, holes, bolt heads), a ring
        round a light centre with or without a dark pupil (a target, a
        manhole cover), a specular highlight in some; on a grey ground, so
        the patch is no white square. Added for model v5's verifier, which
        took a cartoon robot's eyes for the target (docs/journal/
        2026-12-06-learned-detector-v5.md)."""
        s = 96  # drawn at 96 px, anti-aliased; the paste scales it
        img = np.full((s, s), int(rng.uniform(110, 255)), np.uint8)
        count = 2 if rng.random() < 0.4 else 1
        for k in range(count):
            r = rng.uniform(0.18, 0.42) * s / count
            cx = s / 2 if count == 1 else s * (0.28 + 0.44 * k) + rng.normal(0, 2)
            cy = s / 2 + rng.normal(0, 3)
            axes = (int(r), int(r * rng.uniform(0.7, 1.0)))
            angle = rng.uniform(0, 180)
            dark = int(rng.uniform(0, 70))
            cv2.ellipse(img, (int(cx), int(cy)), axes, angle, 0, 360, dark, -1, cv2.LINE_AA)
            if rng.random() < 0.5:  # a ring: a light centre, maybe a dark pupil in it
                inner = (max(1, int(axes[0] * rng.uniform(0.5, 0.8))), max(1, int(axes[1] * rng.uniform(0.5, 0.8))))
                cv2.ellipse(img, (int(cx), int(cy)), inner, angle, 0, 360, int(rng.uniform(150, 255)), -1, cv2.LINE_AA)
                if rng.random() < 0.6:
                    pupil = (max(1, inner[0] // 2), max(1, inner[1] // 2))
                    cv2.ellipse(img, (int(cx), int(cy)), pupil, angle, 0, 360, dark, -1, cv2.LINE_AA)
            if rng.random() < 0.6:  # a highlight
                hr = max(1, int(r * rng.uniform(0.1, 0.3)))
                hx, hy = cx + rng.uniform(-0.4, 0.4) * r, cy + rng.uniform(-0.4, 0.4) * r
                cv2.circle(img, (int(hx), int(hy)), hr, 255, -1, cv2.LINE_AA)
        return img, False

    def patch(self, rng):
        if self.round_share > 0 and rng.random() < self.round_share:
            return self.round_patch(rng)
        kind = rng.choice(["board", "chessboard", "aruco", "grid", "ring", "bars"],
                          p=[0.2, 0.15, 0.25, 0.15, 0.1, 0.15])
        if kind == "board":
            # A calibration board as photographed (model v3): 5-12 squares a
            # side, large in the frame, often cut by the crop's edge.
            r, c = int(rng.integers(5, 11)), int(rng.integers(6, 13))
            cells = (((np.arange(r)[:, None] + np.arange(c)[None, :] + int(rng.integers(0, 2))) % 2) * 255)
            return self._with_margin(cells.astype(np.uint8), rng), True
        if kind == "chessboard":
            r, c = int(rng.integers(2, 10)), int(rng.integers(2, 10))
            cells = (((np.arange(r)[:, None] + np.arange(c)[None, :]) % 2) * 255).astype(np.uint8)
            return self._with_margin(cells, rng), False
        if kind == "aruco":
            name = ARUCO_DICTS[int(rng.integers(0, len(ARUCO_DICTS)))]
            d = self.dicts[name]
            count = d.bytesList.shape[0]
            while True:
                i = int(rng.integers(0, count))
                if not (name == self.dict_name and i == self.target_id):
                    break
            return self._with_margin(cv2.aruco.drawMarker(d, i, d.markerSize + 2), rng), False
        if kind == "grid":
            n = int(rng.integers(3, 8))
            while True:
                code = rng.random((n, n)) < 0.5
                if n != self.bits or not any((code == t).all() for t in self.target_codes):
                    break
            cells = np.zeros((n + 2, n + 2), np.uint8)
            cells[1:-1, 1:-1] = code * 255
            return self._with_margin(cells, rng), False
        if kind == "ring":
            cells = np.zeros((6, 6), np.uint8)
            if rng.random() < 0.5:
                cells[2:4, 2:4] = 255 * (rng.random((2, 2)) < 0.5)
            return self._with_margin(cells, rng), False
        h, w = int(rng.integers(24, 64)), int(rng.integers(24, 64))
        img = np.full((h, w), 255, np.uint8)
        for _ in range(int(rng.integers(2, 8))):
            y, x = int(rng.integers(0, h)), int(rng.integers(0, w))
            cv2.rectangle(img, (x, y), (x + int(rng.integers(2, w // 2)), y + int(rng.integers(2, h // 3))), 0, -1)
        return img, False

    def paste(self, rng, img, keep_out):
        """Pastes 1-3 patches into `img` (uint8, in place) under a random
        perspective, away from the box `keep_out` (lo, hi or None)."""
        H, W = img.shape
        for _ in range(int(rng.integers(1, 4))):
            p, large = self.patch(rng)
            side = rng.uniform(100, 420) if large else rng.uniform(10, 110)
            for _attempt in range(8):
                cx, cy = rng.uniform(0, W), rng.uniform(0, H)
                lo, hi = np.array([cx - side, cy - side]), np.array([cx + side, cy + side])
                if keep_out is None or (hi < keep_out[0]).any() or (lo > keep_out[1]).any():
                    break
            else:
                continue
            ph, pw = p.shape
            src = np.float32([[0, 0], [pw, 0], [pw, ph], [0, ph]])
            a = rng.uniform(0, 2 * math.pi)
            scale = side / max(pw, ph)
            base = np.array([[-pw, -ph], [pw, -ph], [pw, ph], [-pw, ph]], float) * 0.5 * scale
            rot = np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
            dst = base @ rot.T * rng.uniform(0.6, 1.0, (4, 1)) ** 0.3 + [cx, cy]
            dst += rng.normal(0, 0.06 * side, dst.shape)  # perspective
            M = cv2.getPerspectiveTransform(src, dst.astype(np.float32))
            warped = cv2.warpPerspective(p.astype(np.float32), M, (W, H), flags=cv2.INTER_AREA
                                         if scale < 1 else cv2.INTER_LINEAR, borderValue=-1.0)
            alpha = cv2.warpPerspective(np.ones_like(p, np.float32), M, (W, H), flags=cv2.INTER_LINEAR)
            # Print contrast in the scene's light: black and white levels near the frame's own.
            lo_v, hi_v = np.percentile(img, 5), np.percentile(img, 95)
            black = rng.uniform(0, max(lo_v, 1) + 20)
            white = rng.uniform(min(hi_v, 250) - 40, 255)
            if white - black < 20:
                white = min(255.0, black + 40)
            shade = black + (np.clip(warped, 0, 255) / 255) * (white - black)
            out = img.astype(np.float32) * (1 - alpha) + shade * alpha
            img[:] = np.clip(out, 0, 255).astype(np.uint8)


# ---- losses, decoding, metrics -------------------------------------------------------------

def focal_loss(pred, heat, weight):
    pred = pred.clamp(1e-4, 1 - 1e-4)
    pos = heat.eq(1).float()
    neg = (1 - pos) * weight
    pos_loss = torch.log(pred) * (1 - pred) ** 2 * pos
    neg_loss = torch.log(1 - pred) * pred ** 2 * (1 - heat) ** 4 * neg
    n = pos.sum().clamp(min=1)
    return -(pos_loss.sum() + neg_loss.sum()) / n


def decode(out, min_conf=0.05, nms_iou=0.45):
    """The C++ decoder's rule (learned_detector.cpp): 8-neighbour peaks at
    or above min_conf, corners, greedy NMS on the boxes. `out`: 11 x gh x gw."""
    heat = out[0]
    gh, gw = heat.shape
    padded = np.pad(heat, 1, constant_values=-1)
    neigh = np.max(np.stack([padded[1 + dy:1 + dy + gh, 1 + dx:1 + dx + gw]
                             for dy in (-1, 0, 1) for dx in (-1, 0, 1) if dy or dx]), axis=0)
    dets = []
    for p, q in zip(*np.nonzero((heat >= min_conf) & (heat >= neigh))):
        c = np.array([(q + out[1, p, q]) * STRIDE, (p + out[2, p, q]) * STRIDE])
        corners = c + CORNER_SCALE * out[3:, p, q].reshape(4, 2)
        dets.append((float(heat[p, q]), corners.min(axis=0), corners.max(axis=0), corners))
    dets.sort(key=lambda d: -d[0])
    kept = []
    for d in dets:
        if all(iou(d[1], d[2], k[1], k[2]) <= nms_iou for k in kept):
            kept.append(d)
    return kept


def iou(a0, a1, b0, b1):
    return box_iou(np.concatenate([a0, a1]), np.concatenate([b0, b1]))


def evaluate(model, rows, images, threshold=0.7):
    """AP@0.5 over the frames' positive targets (ignored ones match nothing
    and cost nothing), and precision/recall at `threshold`."""
    model.eval()
    scored, positives, tp_at, fp_at = [], 0, 0, 0
    far, far_at = 0, 0  # positives 10 m or more away (the search altitude), and those found at `threshold`
    with torch.no_grad():
        for i in range(0, len(rows), 16):
            x = torch.from_numpy(images[i:i + 16].astype(np.float32) / 255)[:, None]
            outs = model(x).numpy()
            for r, out in zip(rows[i:i + 16], outs):
                role = target_role(r)
                gt = None
                if role != "none":
                    b = r["target"]["box"]
                    gt = (np.array(b[:2]), np.array(b[2:]))
                positives += role == "positive"
                far += role == "positive" and r["distance"] >= 10
                matched = False
                for conf, lo, hi, _ in decode(out):
                    hit = gt is not None and iou(lo, hi, *gt) >= 0.5
                    if hit and role == "ignore":
                        continue
                    is_tp = hit and not matched
                    matched = matched or hit
                    scored.append((conf, is_tp))
                    if conf >= threshold:
                        tp_at += is_tp
                        fp_at += not is_tp
                        far_at += is_tp and r["distance"] >= 10
    model.train()
    return {
        "ap50": round(average_precision(scored, positives), 4),
        "precision_at_0.7": round(tp_at / max(1, tp_at + fp_at), 4),
        "recall_at_0.7": round(tp_at / max(1, positives), 4),
        "far_recall_at_0.7": round(far_at / max(1, far), 4),
        "positives": positives,
        "frames": len(rows),
    }


# ---- main ----------------------------------------------------------------------------------

def main():
    global CROP_W, CROP_H
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("dataset", help="a landing_scenario dataset directory")
    ap.add_argument("--out", required=True, help="the ONNX model to write (its manifest goes beside it)")
    ap.add_argument("--steps", type=int, default=6000)
    ap.add_argument("--batch", type=int, default=32)
    ap.add_argument("--lr", type=float, default=3e-3)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--eval-every", type=int, default=1000)
    ap.add_argument("--positive-fraction", type=float, default=0.5,
                    help="share of each batch drawn from frames with a taught target")
    ap.add_argument("--crop", default="256x192", help="training crop WxH (multiples of 32)")
    ap.add_argument("--width", type=float, default=1.0, help="the network's channel multiplier")
    ap.add_argument("--stem", default="12,24", help="channels of the first two layers before --width "
                    "(model v3: 16,32; with --patchify only the second is used)")
    ap.add_argument("--patchify", action="store_true",
                    help="one 4x4 stride-4 convolution as the stem (model v5: half model v4's time in OpenCV's DNN)")
    ap.add_argument("--no-negatives", action="store_true", help="paste no hard negatives")
    ap.add_argument("--preview", help="write a PNG of 32 training crops with their targets and stop")
    ap.add_argument("--vectors", help="directory for stored frames and PyTorch's outputs (C++ cross-check)")
    a = ap.parse_args()

    try:
        CROP_W, CROP_H = (int(v) for v in a.crop.lower().split("x"))
    except ValueError:
        sys.exit(f"train_detector: --crop {a.crop}: expected WxH")
    if CROP_W % 32 or CROP_H % 32 or CROP_W <= 0 or CROP_H <= 0:
        sys.exit(f"train_detector: --crop {a.crop}: both sides must be positive multiples of 32")
    os.makedirs(os.path.dirname(os.path.abspath(a.out)), exist_ok=True)
    meta_path = os.path.join(a.dataset, "dataset.json")
    if not os.path.isfile(meta_path):
        sys.exit(f"train_detector: {meta_path}: missing (not a landing_scenario dataset)")
    meta = json.load(open(meta_path))
    torch.manual_seed(a.seed)
    torch.set_num_threads(a.threads)
    torch.use_deterministic_algorithms(True)
    rng = np.random.default_rng(a.seed)
    started = time.time()
    train_rows, train_images = load(a.dataset, {"train"})
    val_rows, val_images = load(a.dataset, {"validation"})
    roles = [target_role(r) for r in train_rows]
    print(f"train: {len(train_rows)} frames ({roles.count('positive')} with the target), "
          f"validation: {len(val_rows)}; loaded in {time.time() - started:.0f} s", flush=True)

    negatives = None if a.no_negatives else HardNegatives(meta["marker"])
    marker_dict = cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, "DICT_" + meta["marker"]["dictionary"]))
    cells = marker_dict.markerSize + 2  # code cells and the black border, a side
    positive_rows = np.array([i for i, r in enumerate(roles) if r == "positive"])

    def draw_batch():
        n_pos = int(round(a.batch * a.positive_fraction)) if len(positive_rows) else 0
        idx = np.concatenate([rng.choice(positive_rows, n_pos), rng.integers(0, len(train_rows), a.batch - n_pos)])
        return [augment(rng, train_images[i], train_rows[i], roles[i], negatives, cells) for i in idx]

    if a.preview:
        tiles = []
        for img, targets in draw_batch():
            tile = cv2.cvtColor(img, cv2.COLOR_GRAY2BGR)
            for corners, role in targets:
                colour = (0, 200, 0) if role == "positive" else (0, 200, 255)
                cv2.polylines(tile, [np.round(corners).astype(np.int32)], True, colour, 1)
            tiles.append(tile)
        rows_ = [np.hstack(tiles[i:i + 4]) for i in range(0, len(tiles) - len(tiles) % 4, 4)]
        cv2.imwrite(a.preview, np.vstack(rows_))
        print(f"wrote {a.preview}")
        return

    try:
        stem = tuple(int(v) for v in a.stem.split(","))
        assert len(stem) == 2 and min(stem) > 0
    except (ValueError, AssertionError):
        sys.exit(f"train_detector: --stem {a.stem}: expected two positive channel counts, e.g. 16,32")
    model = MarkerNet(a.width, stem, a.patchify)
    params = sum(p.numel() for p in model.parameters())
    opt = torch.optim.AdamW(model.parameters(), lr=a.lr, weight_decay=1e-4)
    sched = torch.optim.lr_scheduler.OneCycleLR(opt, max_lr=a.lr, total_steps=a.steps, pct_start=0.05)
    history = []
    t0 = time.time()
    for step in range(1, a.steps + 1):
        xs, heats, weights, regs, masks = [], [], [], [], []
        for img, targets in draw_batch():
            h, wgt, reg, m = make_targets(CROP_H, CROP_W, targets)
            xs.append(img)
            heats.append(h), weights.append(wgt), regs.append(reg), masks.append(m)
        x = torch.from_numpy(np.stack(xs).astype(np.float32) / 255)[:, None]
        heat = torch.from_numpy(np.stack(heats))
        weight = torch.from_numpy(np.stack(weights))
        reg = torch.from_numpy(np.stack(regs))
        mask = torch.from_numpy(np.stack(masks))[:, None]
        out = model(x)
        l_heat = focal_loss(out[:, 0], heat, weight)
        n = mask.sum().clamp(min=1)
        l_off = (torch.abs(out[:, 1:3] - reg[:, 0:2]) * mask).sum() / n
        l_corner = (torch.abs(out[:, 3:] - reg[:, 2:]) * mask).sum() / n
        loss = l_heat + l_off + l_corner
        opt.zero_grad()
        loss.backward()
        opt.step()
        sched.step()
        if step % 100 == 0:
            rate = step / (time.time() - t0)
            print(f"step {step}/{a.steps}  loss {loss.item():.3f} (heat {l_heat.item():.3f}, offset "
                  f"{l_off.item():.3f}, corners {l_corner.item():.3f})  {rate:.1f} steps/s, "
                  f"{(a.steps - step) / rate / 60:.1f} min left", flush=True)
        if step % a.eval_every == 0 or step == a.steps:
            m = evaluate(model, val_rows, val_images)
            m["step"] = step
            history.append(m)
            print(f"validation at step {step}: {m}", flush=True)
    train_s = time.time() - t0

    model.eval()
    export_onnx(model, a.out, INPUT_H, INPUT_W)
    blob = open(a.out, "rb").read()
    manifest = {
        "format": "touchdown-detector/1",
        "marker": meta["marker"],
        "input": {"width": INPUT_W, "height": INPUT_H, "channels": 1, "scale": "grey level / 255",
                  "pad_value": PAD_VALUE, "resize": "letterbox (aspect kept), area when shrinking"},
        "output": {"stride": STRIDE, "channels": CHANNELS, "corner_scale": CORNER_SCALE,
                   "layout": "0 heat (sigmoid); 1-2 centre offset [cells]; 3-10 corners - centre "
                             "[corner_scale input px], clockwise from the one nearest the top-left"},
        "model": {"file": os.path.basename(a.out), "bytes": len(blob),
                  "sha256": hashlib.sha256(blob).hexdigest(), "parameters": params, "opset": 11,
                  "architecture": f"MarkerNet(width={a.width}, stem={stem}, patchify={a.patchify}) "
                                  "(tools/detector_model.py)"},
        "dataset": {"seed": meta["seed"], "count": meta["count"], "splits": meta["splits"],
                    "command": f"landing_scenario dataset --out DIR --count {meta['count']} --seed {meta['seed']} "
                               f"--marker {meta['marker']['dictionary']}:{meta['marker']['id']}"},
        "training": {"seed": a.seed, "steps": a.steps, "batch": a.batch, "lr": a.lr, "threads": a.threads,
                     "positive_fraction": a.positive_fraction, "width": a.width, "stem": list(stem),
                     "patchify": a.patchify,
                     "scale_aware_degradation": True,
                     "hard_negatives": negatives is not None,
                     "crop": [CROP_W, CROP_H], "optimizer": "AdamW, one-cycle", "torch": torch.__version__,
                     "seconds": round(train_s), "command": " ".join(["tools/train_detector.py"] + sys.argv[1:])},
        "metrics": {"validation": history[-1], "history": history},
    }
    with open(os.path.splitext(a.out)[0] + ".json", "w") as f:
        json.dump(manifest, f, indent=2)
        f.write("\n")
    print(f"wrote {a.out} ({len(blob)} bytes, {params} parameters) in {train_s / 60:.1f} min of training; "
          f"validation {history[-1]}")

    if a.vectors:
        write_vectors(model, a.vectors, val_rows, val_images)


def write_vectors(model, directory, rows, images):
    """Two validation frames (one with the target, one without) as PNG, and
    PyTorch's output for each as raw little-endian float32 (11 x 60 x 80)."""
    os.makedirs(directory, exist_ok=True)
    with_target = next(i for i, r in enumerate(rows) if target_role(r) == "positive")
    without = next(i for i, r in enumerate(rows) if target_role(r) == "none")
    index = []
    with torch.no_grad():
        for name, i in (("with_target", with_target), ("without_target", without)):
            cv2.imwrite(os.path.join(directory, name + ".png"), images[i])
            x = torch.from_numpy(images[i].astype(np.float32) / 255)[None, None]
            out = model(x)[0].numpy().astype("<f4")
            out.tofile(os.path.join(directory, name + ".bin"))
            index.append({"image": name + ".png", "output": name + ".bin", "shape": list(out.shape),
                          "dataset_index": rows[i]["index"]})
    with open(os.path.join(directory, "vectors.json"), "w") as f:
        json.dump(index, f, indent=2)
        f.write("\n")


if __name__ == "__main__":
    main()

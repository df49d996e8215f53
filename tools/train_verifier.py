#!/usr/bin/python3
"""Trains the learned detector's second stage (the verifier) and names it in the model's manifest.

    landing_scenario dataset --out DS --count 10000 --seed 1
    /usr/bin/python3 tools/train_verifier.py DS --model data/models/marker-4x4_50-0.onnx \
        [--vectors tests/data/detector]

The first stage (tools/train_detector.py) proposes: its heat map at stride 8
finds a marker 10 m away but cannot read its code, and scores the target
and a look-alike beside it alike. The verifier decides: each proposal's
four corners warp the frame to a 32 x 32 patch at the frame's own
resolution (tools/detector_model.py, extract_patch) and a small CNN says
whether it is the target; its probability becomes the detection's
confidence (src/scenario/learned_detector.cpp).

Training patches, from the dataset's train split:
  positives  the target where the frame teaches it (train_detector's
             target_role "positive"), through its true corners jittered by
             4 % of its side, and through the first stage's own corners
             on it (what the verifier meets at run time);
  negatives  every distractor in view (look-alikes: the target's code with
             cells flipped; other ids; random patterns) through its true,
             jittered corners; the first stage's proposals on anything
             else (background, objects, glare); and hard negatives drawn
             here (calibration boards, other dictionaries' markers, bit
             grids, codeless squares, and with --round-negatives discs,
             rings and eyes: train_detector's HardNegatives)
             under a random perspective on a frame's background.
Each sample gets a random quarter turn (the corners rolled: the proposal's
corner order says nothing of the code's rotation), blur and noise.

Writes VERIFIER.onnx beside the model (opset 11; the model's name with
"-verifier"), rewrites the model's manifest with format
"touchdown-detector/2" and a "verifier" object (file, sha256, patch,
margin, thresholds, training, metrics: docs/formats.md), and with
--vectors, stored patches and PyTorch's outputs for the C++ cross-check.
A training-time tool (python3-torch, python3-onnx, python3-opencv);
deterministic for a seed on one machine and thread count.
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
from detector_model import MARGIN_CELLS, MIN_RANGE, PATCH, VerifierNet, export_verifier_onnx, \
    extract_patch, normalise_patch  # noqa: E402
from train_detector import HardNegatives, decode, load, min_side, target_role  # noqa: E402

KINDS = ("target", "target-proposal", "lookalike", "wrong_id", "pattern", "proposal")


def stage1(net, image, proposal, max_proposals):
    """The first stage's proposals on a 640 x 480 frame, as the C++ detector
    makes them: peaks at or above `proposal`, NMS, the highest `max_proposals`."""
    net.setInput((image.astype(np.float32) / 255)[None, None])
    out = net.forward()[0]
    return decode(out, min_conf=proposal)[:max_proposals]


def box_of(corners):
    c = np.asarray(corners, float)
    return np.concatenate([c.min(axis=0), c.max(axis=0)])


def collect(rows, images, net, proposal, max_proposals):
    """(frame, corners, label, kind, distance, heat) for every sample the split gives."""
    samples = []
    for i, r in enumerate(rows):
        role = target_role(r)
        t = r["target"]
        if role == "positive":
            samples.append((i, np.asarray(t["corners"], float), 1, "target", r["distance"], None))
        for d in r.get("distractors", []):
            if d.get("in_view") and d.get("corners") and d.get("inside_fraction", 1) >= 0.85 and \
                    d.get("visible_fraction", 1) >= 0.6 and min_side(d["corners"]) >= 6:
                samples.append((i, np.asarray(d["corners"], float), 0, d["kind"], r["distance"], None))
        t_box = np.array(t["box"], float) if t["in_view"] and t["corners"] else None
        for heat, lo, hi, corners in stage1(net, images[i], proposal, max_proposals):
            b = np.concatenate([lo, hi])
            if t_box is not None and box_iou(b, t_box) >= 0.5:
                if role == "positive":
                    samples.append((i, corners, 1, "target-proposal", r["distance"], heat))
                continue  # a target the frame does not teach: neither label
            kind = "proposal"
            for d in r.get("distractors", []):
                if d.get("in_view") and d.get("corners") and box_iou(b, box_of(d["corners"])) >= 0.5:
                    kind = d["kind"]
            samples.append((i, corners, 0, kind, r["distance"], heat))
    return samples


def drawn_negative(rng, negatives, background, cells):
    """A hard negative drawn under a random perspective onto a frame's
    background, with the corners a proposal on it would have."""
    p, large = negatives.patch(rng)
    ph, pw = p.shape
    # A 192 x 192 window of the frame is enough room (and 8x cheaper to warp).
    by, bx = int(rng.integers(0, background.shape[0] - 191)), int(rng.integers(0, background.shape[1] - 191))
    img = background[by:by + 192, bx:bx + 192].copy()
    h, w = img.shape
    side = rng.uniform(14, 90)
    cx, cy = rng.uniform(side, w - side), rng.uniform(side, h - side)
    if large:  # a window of the board, as a proposal on part of it would see
        k = rng.uniform(0.25, 0.6)
        x0, y0 = rng.uniform(0, pw * (1 - k)), rng.uniform(0, ph * (1 - k))
        src = np.float32([[x0, y0], [x0 + k * pw, y0], [x0 + k * pw, y0 + k * ph], [x0, y0 + k * ph]])
    else:
        src = np.float32([[0, 0], [pw, 0], [pw, ph], [0, ph]])
    a = rng.uniform(0, 2 * math.pi)
    rot = np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
    dst = (np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], float) * 0.5 * side) @ rot.T + [cx, cy]
    dst += rng.normal(0, 0.05 * side, dst.shape)
    M = cv2.getPerspectiveTransform(src, dst.astype(np.float32))
    warped = cv2.warpPerspective(p.astype(np.float32), M, (w, h), flags=cv2.INTER_AREA, borderValue=-1.0)
    alpha = cv2.warpPerspective(np.ones_like(p, np.float32), M, (w, h), flags=cv2.INTER_LINEAR)
    black, white = rng.uniform(0, 80), rng.uniform(150, 255)
    shade = black + np.clip(warped, 0, 255) / 255 * (white - black)
    img = np.clip(img.astype(np.float32) * (1 - alpha) + shade * alpha, 0, 255).astype(np.uint8)
    # The proposal's corners: the drawn square shrunk to where a code's black
    # border would sit inside a one-cell margin, with the first stage's error.
    centre = dst.mean(axis=0)
    corners = centre + (dst - centre) * rng.uniform(0.7, 1.0) + rng.normal(0, 0.04 * side, dst.shape)
    return img, corners


def drawn_marker(rng, negatives, background, flips):
    """The target's code drawn under a random perspective onto a 192 x 192
    window of a frame, with `flips` of its code cells flipped (0: the
    target itself; 1-3: a look-alike), small, blurred and noisy as far
    markers are; returns the image and the code's corners with the first
    stage's error (4 % of a side)."""
    code = negatives.target_codes[int(rng.integers(0, 4))].copy()
    n = code.shape[0]
    for k in rng.choice(n * n, flips, replace=False):
        code[k // n, k % n] = ~code[k // n, k % n]
    cells = np.zeros((n + 2, n + 2), np.uint8)
    cells[1:-1, 1:-1] = code * 255
    px = 8
    img_code = cv2.resize(cells, ((n + 2) * px, (n + 2) * px), interpolation=cv2.INTER_NEAREST)
    img_code = cv2.copyMakeBorder(img_code, px, px, px, px, cv2.BORDER_CONSTANT, value=255)
    s = img_code.shape[0]
    by, bx = int(rng.integers(0, background.shape[0] - 191)), int(rng.integers(0, background.shape[1] - 191))
    img = background[by:by + 192, bx:bx + 192].copy()
    side = rng.uniform(14, 80)  # the code's side [px]
    full = side * s / ((n + 2) * px)
    cx, cy = rng.uniform(0.75 * full, 192 - 0.75 * full), rng.uniform(0.75 * full, 192 - 0.75 * full)
    a = rng.uniform(0, 2 * math.pi)
    rot = np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
    dst = (np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], float) * 0.5 * full) @ rot.T + [cx, cy]
    dst += rng.normal(0, 0.04 * full, dst.shape)
    M = cv2.getPerspectiveTransform(np.float32([[0, 0], [s, 0], [s, s], [0, s]]), dst.astype(np.float32))
    warped = cv2.warpPerspective(img_code.astype(np.float32), M, (192, 192), flags=cv2.INTER_LINEAR,
                                 borderMode=cv2.BORDER_REPLICATE)
    alpha = cv2.warpPerspective(np.ones_like(img_code, np.float32), M, (192, 192), flags=cv2.INTER_LINEAR)
    black, white = rng.uniform(0, 90), rng.uniform(140, 255)
    shade = black + warped / 255 * (white - black)
    out = img.astype(np.float32) * (1 - alpha) + shade * alpha
    if rng.random() < 0.5:
        out = cv2.GaussianBlur(out, (0, 0), rng.uniform(0.4, 1.2))
    out = np.clip(out, 0, 255).astype(np.uint8)
    inner = np.float32([[px, px], [s - px, px], [s - px, s - px], [px, s - px]])
    corners = cv2.perspectiveTransform(inner[None], M)[0].astype(float)
    corners += rng.normal(0, 0.04 * side, corners.shape)
    return out, corners


def make_patch(rng, image, corners, cells, jitter):
    c = np.asarray(corners, float)
    if jitter:
        c = c + rng.normal(0, 0.04 * min_side(c), c.shape)
    c = np.roll(c, -int(rng.integers(0, 4)), axis=0)  # a quarter turn of the code in the patch
    p = extract_patch(image, c, cells)
    if p is None:
        return None
    # Degrade the patch's grey levels (then normalise again): blur, noise.
    f = p * 255
    if rng.random() < 0.3:
        f = cv2.GaussianBlur(f, (0, 0), rng.uniform(0.3, 1.0))
    if rng.random() < 0.5:
        f = f + rng.normal(0, rng.uniform(1, 8), f.shape).astype(np.float32)
    return normalise_patch(np.clip(f, 0, 255))


def score(model, images, samples, cells):
    """The verifier's probability for each sample, patches without augmentation."""
    model.eval()
    out = []
    with torch.no_grad():
        for k in range(0, len(samples), 256):
            batch = [extract_patch(images[s[0]], s[1], cells) for s in samples[k:k + 256]]
            x = np.stack([b if b is not None else np.zeros((PATCH, PATCH), np.float32) for b in batch])
            p = model(torch.from_numpy(x)[:, None]).numpy()[:, 0]
            out.extend(float(v) if b is not None else 0.0 for v, b in zip(p, batch))
    model.train()
    return out


def evaluate(model, rows, images, samples, cells):
    """Acceptance at 0.5 and 0.7 per kind (and far: 10 m or more), and the
    two-stage detector's AP@0.5 and recall/precision at 0.7 on the frames,
    against the first stage alone (its heat as the confidence)."""
    p = score(model, images, samples, cells)
    res = {}
    for kind in KINDS:
        for far in (False, True):
            sel = [v for v, s in zip(p, samples) if s[3] == kind and (not far or s[4] >= 10)]
            if sel:
                key = kind + (" far" if far else "")
                res[key] = {"n": len(sel), "accepted_at_0.5": round(float(np.mean(np.array(sel) >= 0.5)), 4),
                            "accepted_at_0.7": round(float(np.mean(np.array(sel) >= 0.7)), 4)}
    # Frames: each frame's proposals (the stage-1 samples) scored by the verifier.
    by_frame = {}
    for v, s in zip(p, samples):
        if s[5] is not None:
            by_frame.setdefault(s[0], []).append((v, s[5], s[2]))
    positives = sum(target_role(r) == "positive" for r in rows)
    far_pos = sum(target_role(r) == "positive" and r["distance"] >= 10 for r in rows)
    for name, col in (("two_stage", 0), ("stage1_only", 1)):
        scored, tp, fp, far_tp = [], 0, 0, 0
        for i, props in by_frame.items():
            matched = False
            for prop in sorted(props, key=lambda q: -q[col]):
                conf, is_t = prop[col], prop[2] == 1
                is_tp = is_t and not matched
                matched = matched or is_t
                scored.append((conf, is_tp))
                if conf >= 0.7:
                    tp += is_tp
                    fp += not is_tp
                    far_tp += is_tp and rows[i]["distance"] >= 10
        res[name] = {"ap50": round(average_precision(scored, positives), 4),
                     "precision_at_0.7": round(tp / max(1, tp + fp), 4),
                     "recall_at_0.7": round(tp / max(1, positives), 4),
                     "far_recall_at_0.7": round(far_tp / max(1, far_pos), 4)}
    return res


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("dataset", help="a landing_scenario dataset directory")
    ap.add_argument("--model", required=True, help="the first stage's ONNX model (its manifest is rewritten)")
    ap.add_argument("--steps", type=int, default=5000)
    ap.add_argument("--batch", type=int, default=128)
    ap.add_argument("--lr", type=float, default=2e-3)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--width", type=float, default=0.75)
    ap.add_argument("--proposal", type=float, default=0.1,
                    help="the first stage's heat that makes a training proposal")
    ap.add_argument("--max-proposals", type=int, default=8, help="training proposals a frame")
    ap.add_argument("--run-proposal", type=float, default=0.15,
                    help="the heat that makes a proposal at run time (the manifest's proposal_threshold)")
    ap.add_argument("--run-max-proposals", type=int, default=4,
                    help="proposals verified a frame at run time (the manifest's max_proposals)")
    ap.add_argument("--round-negatives", type=float, default=0.25,
                    help="share of the drawn hard negatives that are round shapes (discs, rings, eyes); "
                         "model v4's verifier: 0")
    ap.add_argument("--state", help="also save the PyTorch weights here (to write vectors again)")
    ap.add_argument("--vectors", help="directory for stored patches and PyTorch's outputs (C++ cross-check)")
    a = ap.parse_args()

    manifest_path = os.path.splitext(a.model)[0] + ".json"
    manifest = json.load(open(manifest_path))
    meta = json.load(open(os.path.join(a.dataset, "dataset.json")))
    if meta["marker"] != manifest["marker"]:
        sys.exit(f"train_verifier: {a.dataset} shows {meta['marker']}, the model detects {manifest['marker']}")
    out_path = os.path.splitext(a.model)[0] + "-verifier.onnx"
    torch.manual_seed(a.seed)
    torch.set_num_threads(a.threads)
    torch.use_deterministic_algorithms(True)
    cv2.setNumThreads(1)
    rng = np.random.default_rng(a.seed)
    cells = cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, "DICT_" + meta["marker"]["dictionary"])).markerSize + 2
    started = time.time()
    train_rows, train_images = load(a.dataset, {"train"})
    val_rows, val_images = load(a.dataset, {"validation"})
    net = cv2.dnn.readNetFromONNX(a.model)
    train = collect(train_rows, train_images, net, a.proposal, a.max_proposals)
    val = collect(val_rows, val_images, net, a.proposal, a.max_proposals)
    counts = {k: sum(s[3] == k for s in train) for k in KINDS}
    print(f"samples: train {len(train)} {counts}, validation {len(val)}; {time.time() - started:.0f} s", flush=True)

    pos = [s for s in train if s[2] == 1]
    neg = [s for s in train if s[2] == 0]
    negatives = HardNegatives(meta["marker"], a.round_negatives)
    model = VerifierNet(a.width)
    params = sum(p.numel() for p in model.parameters())
    opt = torch.optim.AdamW(model.parameters(), lr=a.lr, weight_decay=1e-4)
    sched = torch.optim.lr_scheduler.OneCycleLR(opt, max_lr=a.lr, total_steps=a.steps, pct_start=0.05)
    loss_fn = torch.nn.BCEWithLogitsLoss()
    t0 = time.time()
    history = []
    for step in range(1, a.steps + 1):
        xs, ys = [], []
        while len(xs) < a.batch:
            u = rng.random()
            if u < 0.45:
                s = pos[int(rng.integers(0, len(pos)))]
                p, y = make_patch(rng, train_images[s[0]], s[1], cells, s[3] == "target"), 1
            elif u < 0.8:
                s = neg[int(rng.integers(0, len(neg)))]
                p, y = make_patch(rng, train_images[s[0]], s[1], cells, s[5] is None), 0
            elif u < 0.9:
                bg = train_images[int(rng.integers(0, len(train_images)))]
                img, corners = drawn_negative(rng, negatives, bg, cells)
                p, y = make_patch(rng, img, corners, cells, False), 0
            else:  # the target drawn, or a look-alike one to three cells off it (half each)
                bg = train_images[int(rng.integers(0, len(train_images)))]
                flips = 0 if rng.random() < 0.5 else int(rng.integers(1, 4))
                img, corners = drawn_marker(rng, negatives, bg, flips)
                p, y = make_patch(rng, img, corners, cells, False), int(flips == 0)
            if p is not None:
                xs.append(p)
                ys.append(y)
        x = torch.from_numpy(np.stack(xs))[:, None]
        y = torch.tensor(ys, dtype=torch.float32)
        loss = loss_fn(model.raw(x), y)
        opt.zero_grad()
        loss.backward()
        opt.step()
        sched.step()
        if step % 200 == 0:
            rate = step / (time.time() - t0)
            print(f"step {step}/{a.steps}  loss {loss.item():.4f}  {rate:.1f} steps/s, "
                  f"{(a.steps - step) / rate / 60:.1f} min left", flush=True)
        if step % 1000 == 0 or step == a.steps:
            m = evaluate(model, val_rows, val_images, val, cells)
            m["step"] = step
            history.append(m)
            print(f"validation at step {step}: {json.dumps(m)}", flush=True)
    train_s = time.time() - t0

    model.eval()
    if a.state:
        torch.save(model.state_dict(), a.state)
    export_verifier_onnx(model, out_path)
    blob = open(out_path, "rb").read()
    manifest["format"] = "touchdown-detector/2"
    manifest["verifier"] = {
        "file": os.path.basename(out_path), "bytes": len(blob), "sha256": hashlib.sha256(blob).hexdigest(),
        "parameters": params, "opset": 11, "architecture": f"VerifierNet(width={a.width}) (tools/detector_model.py)",
        "patch": PATCH, "margin_cells": MARGIN_CELLS, "min_range": MIN_RANGE,
        "proposal_threshold": a.run_proposal, "max_proposals": a.run_max_proposals,
        "layout": "input 1 x 1 x patch x patch: the frame warped through a proposal's corners (its code "
                  "square inside margin_cells of margin), (v - min) / max(max - min, min_range); output 1 x 1: "
                  "the probability that it is the target (the detection's confidence)",
        "training": {"seed": a.seed, "steps": a.steps, "batch": a.batch, "lr": a.lr, "threads": a.threads,
                     "width": a.width, "proposal_threshold": a.proposal, "max_proposals": a.max_proposals,
                     "drawn": "hard negatives 10 %, the target or a look-alike drawn 10 % of each batch",
                     "round_negatives": a.round_negatives,
                     "optimizer": "AdamW, one-cycle", "torch": torch.__version__,
                     "seconds": round(train_s), "samples": counts,
                     "dataset": {"seed": meta["seed"], "count": meta["count"]},
                     "command": " ".join(["tools/train_verifier.py"] + sys.argv[1:])},
        "metrics": {"validation": history[-1], "history": history},
    }
    with open(manifest_path, "w") as f:
        json.dump(manifest, f, indent=2)
        f.write("\n")
    print(f"wrote {out_path} ({len(blob)} bytes, {params} parameters) in {train_s / 60:.1f} min; "
          f"rewrote {manifest_path}")
    if a.vectors:
        write_vectors(model, a.vectors, val_rows, val_images, val, cells)


def write_vectors(model, directory, rows, images, samples, cells):
    """Two validation proposals (the target, and a distractor) as their frame
    (PNG), corners, patch (raw float32) and PyTorch's probability."""
    os.makedirs(directory, exist_ok=True)
    # Probabilities off the sigmoid's flat ends, where 1e-4 says something
    # about the logit: a target the verifier accepts short of certain, and
    # a look-alike it rejects short of certain.
    p = score(model, images, samples, cells)
    model.eval()

    def pick(want, lo, hi):
        return next((s for v, s in zip(p, samples) if want(s) and lo < v < hi), None) or \
            next(s for s in samples if want(s))

    picks = [("verifier_target", pick(lambda s: s[3] == "target-proposal", 0.7, 0.99)),
             ("verifier_lookalike", pick(lambda s: s[3] == "lookalike", 0.01, 0.5))]
    index = []
    with torch.no_grad():
        for name, s in picks:
            cv2.imwrite(os.path.join(directory, name + ".png"), images[s[0]])
            patch = extract_patch(images[s[0]], s[1], cells)
            patch.astype("<f4").tofile(os.path.join(directory, name + ".patch.bin"))
            prob = float(model(torch.from_numpy(patch)[None, None])[0, 0])
            index.append({"image": name + ".png", "patch": name + ".patch.bin", "corners": np.asarray(s[1]).tolist(),
                          "probability": prob, "kind": s[3], "dataset_index": rows[s[0]]["index"]})
    with open(os.path.join(directory, "verifier_vectors.json"), "w") as f:
        json.dump(index, f, indent=2)
        f.write("\n")


if __name__ == "__main__":
    main()

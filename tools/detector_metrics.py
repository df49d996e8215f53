"""Detection metrics shared by touchdown's detector tools (train_detector.py,
photo_check.py). numpy only: no torch, so photo_check.py runs without it.

The C++ side has its own (src/scenario/detector_bench.cpp); both follow the
PASCAL VOC definitions (Everingham et al., "The PASCAL Visual Object Classes
Challenge", 2010: IoU >= 0.5 to match, all-point interpolated AP)."""
import numpy as np


def box_iou(a, b):
    """Intersection over union of two boxes [x0, y0, x1, y1]."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    lo, hi = np.maximum(a[:2], b[:2]), np.minimum(a[2:], b[2:])
    inter = max(0.0, hi[0] - lo[0]) * max(0.0, hi[1] - lo[1])
    union = np.prod(np.maximum(a[2:] - a[:2], 0)) + np.prod(np.maximum(b[2:] - b[:2], 0)) - inter
    return inter / union if union > 0 else 0.0


def average_precision(scored, positives):
    """All-point interpolated AP (PASCAL VOC 2010+) from (score, is_tp)."""
    if positives == 0:
        return float("nan")
    scored = sorted(scored, key=lambda s: -s[0])
    tp = np.cumsum([s[1] for s in scored])
    fp = np.cumsum([not s[1] for s in scored])
    recall = tp / positives
    precision = tp / np.maximum(tp + fp, 1)
    r = np.concatenate([[0], recall, [recall[-1] if len(recall) else 0]])
    p = np.concatenate([[1], precision, [0]])
    for i in range(len(p) - 2, -1, -1):
        p[i] = max(p[i], p[i + 1])
    return float(np.sum((r[1:] - r[:-1]) * p[1:]))

"""The learned marker detector's network (tools/train_detector.py trains it).

A small one-stage centre-heatmap detector after CenterNet (Zhou, Wang and
Krähenbühl, "Objects as Points", 2019): a MobileNet-like backbone of
depthwise-separable convolutions (Howard et al., 2017) to stride 32, a
top-down path back to stride 8 (feature-pyramid style: upsample and add),
and one head of 11 channels per stride-8 cell:
  0      centre heatmap (sigmoid, in the exported graph)
  1-2    the centre's offset within its cell [cells]
  3-10   the four corners relative to the centre [CORNER_SCALE input px],
         clockwise from the one nearest the image's top-left.
The layout is what src/scenario/learned_detector.cpp decodes; the manifest
beside the ONNX file carries STRIDE and CORNER_SCALE.
"""
import torch
from torch import nn

STRIDE = 8
CORNER_SCALE = 64.0
CHANNELS = 11


def conv_bn(cin, cout, k=3, s=1, groups=1, pad=None):
    return nn.Sequential(
        nn.Conv2d(cin, cout, k, s, k // 2 if pad is None else pad, groups=groups, bias=False),
        nn.BatchNorm2d(cout),
        nn.ReLU(inplace=True),
    )


def dw_sep(cin, cout, s=1):
    """Depthwise 3x3 (stride s) then pointwise 1x1."""
    return nn.Sequential(conv_bn(cin, cin, 3, s, groups=cin), conv_bn(cin, cout, 1))


class Residual(nn.Module):
    def __init__(self, c):
        super().__init__()
        self.body = dw_sep(c, c)

    def forward(self, x):
        return x + self.body(x)


class MarkerNet(nn.Module):
    def __init__(self, width=1.0, stem=(12, 24), patchify=False):
        """`width` multiplies every layer's channels; `stem` is the first two
        layers' (strides 2 and 4) before it: model v3 widened them to
        (16, 32) to keep a far marker's code cells (3-5 px) apart.

        `patchify` (model v5) replaces those two layers by one 4 x 4
        convolution of stride 4 with stem[1] channels: each output cell is a
        linear map of its own 16 pixels (lossless when stem[1] >= 16), and
        it costs a fifth of the 3 x 3 stride-2 convolution plus the stride-4
        pointwise layer, which were 36 % of model v4's time in OpenCV's DNN
        (docs/journal/marker-detectors.md)."""
        super().__init__()
        c = [int(round(v * width)) for v in (*stem, 32, 64, 96)]
        if patchify:
            self.stem = conv_bn(1, c[1], 4, 4, pad=0)  # stride 4
        else:
            self.stem = nn.Sequential(conv_bn(1, c[0], 3, 2), dw_sep(c[0], c[1], 2))  # stride 4
        self.s8 = nn.Sequential(dw_sep(c[1], c[2], 2), Residual(c[2]))
        self.s16 = nn.Sequential(dw_sep(c[2], c[3], 2), Residual(c[3]), Residual(c[3]))
        self.s32 = nn.Sequential(dw_sep(c[3], c[4], 2), Residual(c[4]), Residual(c[4]))
        self.lat32 = conv_bn(c[4], c[3], 1)
        self.lat16 = conv_bn(c[3], c[2], 1)
        self.up = nn.Upsample(scale_factor=2, mode="nearest")
        self.mix16 = Residual(c[3])
        self.mix8 = nn.Sequential(Residual(c[2]), dw_sep(c[2], c[2]))
        self.head = nn.Conv2d(c[2], CHANNELS, 1)
        with torch.no_grad():  # CenterNet's prior: little heat at the start
            self.head.bias.zero_()
            self.head.bias[0] = -4.0

    def raw(self, x):
        x8 = self.s8(self.stem(x))
        x16 = self.s16(x8)
        x32 = self.s32(x16)
        y16 = self.mix16(x16 + self.up(self.lat32(x32)))
        y8 = self.mix8(x8 + self.up(self.lat16(y16)))
        return self.head(y8)

    def forward(self, x):
        out = self.raw(x)
        return torch.cat([torch.sigmoid(out[:, :1]), out[:, 1:]], dim=1)


def export_onnx(model, path, height, width):
    """ONNX at opset 11 (OpenCV 4.6's DNN reads it), input "image"
    1x1xHxW, output "out". The exporter's constant folding shares equal
    folded constants through Identity nodes, which OpenCV 4.6 cannot read:
    each becomes a copy of its initializer."""
    model.eval()
    x = torch.zeros(1, 1, height, width)
    torch.onnx.export(model, x, path, opset_version=11, input_names=["image"], output_names=["out"],
                      do_constant_folding=True)
    inline_identities(path)


def inline_identities(path):
    """Replaces each Identity node on an initializer by a copy of it (OpenCV
    4.6 cannot read such nodes) and checks the model."""
    import onnx
    from onnx import numpy_helper

    m = onnx.load(path)
    inits = {i.name: i for i in m.graph.initializer}
    keep = []
    for n in m.graph.node:
        if n.op_type == "Identity" and n.input[0] in inits:
            copy = numpy_helper.from_array(numpy_helper.to_array(inits[n.input[0]]), n.output[0])
            m.graph.initializer.append(copy)
        else:
            keep.append(n)
    del m.graph.node[:]
    m.graph.node.extend(keep)
    onnx.checker.check_model(m)
    onnx.save(m, path)


# ---- the second stage: a verifier on the corner-warped patch ------------------------------
# The heat map at stride 8 finds a far marker but cannot read its 4 x 4 code
# (4-7 px cells): it scores the target and a look-alike beside it alike
# (docs/journal/2026-11-29-learned-detector-v3.md). The verifier reads each
# proposal at the frame's own resolution: the frame warped through the
# proposal's four corners (grown by one code cell of white margin) to a
# PATCH x PATCH square, min-max normalised, and a small CNN that says
# whether it is the target. src/scenario/learned_detector.cpp extracts the
# patch with the same OpenCV calls (extract_patch), so a stored frame and
# corners give the same patch in both, within float rounding.

PATCH = 32
MARGIN_CELLS = 1
MIN_RANGE = 8.0  # grey levels: the normalisation never stretches less contrast than this


def extract_patch(gray, corners, cells, patch=PATCH, margin=MARGIN_CELLS):
    """The verifier's input for a proposal: `gray` (uint8 H x W), `corners`
    (4 x 2 frame px, the code's black border, clockwise) -> float32 patch x
    patch in [0, 1], or None when the proposal lies outside the frame.

    Steps (the C++ twin, detail::extract_patch, follows them one for one):
    the quad grown by the margin about its centre bounds a crop (1 px more
    each side, clipped to the frame); when the code is more than twice the
    patch's code size the crop is shrunk by area averaging first (no
    aliasing); the crop is warped so the corners land on the patch's code
    square; bilinear, border replicated; then (v - min) / max(max - min, 8)."""
    import math

    import cv2
    import numpy as np

    c = np.asarray(corners, np.float64)
    h, w = gray.shape
    total = cells + 2 * margin
    m = patch * margin / total
    inner = patch - 2 * m
    side = np.mean([np.linalg.norm(c[i] - c[(i + 1) % 4]) for i in range(4)])
    if not np.isfinite(side) or side < 1:
        return None
    centre = c.mean(axis=0)
    quad = centre + (c - centre) * (total / cells)
    x0 = max(0, int(np.floor(quad[:, 0].min())) - 1)
    y0 = max(0, int(np.floor(quad[:, 1].min())) - 1)
    x1 = min(w, int(np.ceil(quad[:, 0].max())) + 2)
    y1 = min(h, int(np.ceil(quad[:, 1].max())) + 2)
    if x1 - x0 < 2 or y1 - y0 < 2:
        return None
    crop = gray[y0:y1, x0:x1]
    c = c - [x0, y0]
    r = 2 * inner / side
    if r < 1:
        cw, ch = x1 - x0, y1 - y0
        # floor(x + 0.5): C++'s std::lround for these positive sizes (Python's
        # round() takes halves to even).
        nw, nh = max(2, int(math.floor(cw * r + 0.5))), max(2, int(math.floor(ch * r + 0.5)))
        crop = cv2.resize(crop, (nw, nh), interpolation=cv2.INTER_AREA)
        c = (c + 0.5) * [nw / cw, nh / ch] - 0.5
    lo, hi = m - 0.5, patch - m - 0.5
    dst = np.float32([[lo, lo], [hi, lo], [hi, hi], [lo, hi]])
    M = cv2.getPerspectiveTransform(c.astype(np.float32), dst)
    p = cv2.warpPerspective(crop, M, (patch, patch), flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)
    return normalise_patch(p)


def normalise_patch(p):
    import numpy as np

    f = p.astype(np.float32)
    lo, hi = float(f.min()), float(f.max())
    return (f - np.float32(lo)) / np.float32(max(hi - lo, MIN_RANGE))


class VerifierNet(nn.Module):
    """Target or not, from a PATCH x PATCH corner-warped proposal: plain 3 x 3
    convolutions to stride 8 (4 px a code cell -> a cell per feature at
    the end), then two linear layers over the whole 4 x 4 map: where each
    cell is matters (the code), so no global pooling."""

    def __init__(self, width=1.0):
        super().__init__()
        c = [int(round(v * width)) for v in (16, 32, 64)]
        self.features = nn.Sequential(
            conv_bn(1, c[0]), conv_bn(c[0], c[1], s=2), conv_bn(c[1], c[1]),
            conv_bn(c[1], c[2], s=2), conv_bn(c[2], c[2]), conv_bn(c[2], c[2], s=2))
        self.classify = nn.Sequential(nn.Flatten(), nn.Linear(c[2] * (PATCH // 8) ** 2, 64), nn.ReLU(inplace=True),
                                      nn.Linear(64, 1))

    def raw(self, x):
        return self.classify(self.features(x))[:, 0]

    def forward(self, x):
        return torch.sigmoid(self.classify(self.features(x)))


def export_verifier_onnx(model, path):
    """The verifier at opset 11: input "patch" 1 x 1 x PATCH x PATCH, output
    "p" 1 x 1 (the probability that the patch is the target)."""
    model.eval()
    x = torch.zeros(1, 1, PATCH, PATCH)
    torch.onnx.export(model, x, path, opset_version=11, input_names=["patch"], output_names=["p"],
                      do_constant_folding=True)
    inline_identities(path)

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


def conv_bn(cin, cout, k=3, s=1, groups=1):
    return nn.Sequential(
        nn.Conv2d(cin, cout, k, s, k // 2, groups=groups, bias=False),
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
    def __init__(self, width=1.0, stem=(12, 24)):
        """`width` multiplies every layer's channels; `stem` is the first two
        layers' (strides 2 and 4) before it: model v3 widened them to
        (16, 32) to keep a far marker's code cells (3-5 px) apart."""
        super().__init__()
        c = [int(round(v * width)) for v in (*stem, 32, 64, 96)]
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
    import onnx
    from onnx import numpy_helper

    model.eval()
    x = torch.zeros(1, 1, height, width)
    torch.onnx.export(model, x, path, opset_version=11, input_names=["image"], output_names=["out"],
                      do_constant_folding=True)
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

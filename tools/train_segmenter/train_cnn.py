"""Trains segmentation.cnn's network for `tilth train-segmenter --model cnn`: a small U-Net
on frames the tool wrote (registered colour and labels on the depth grid), exported as
ONNX with the sidecar (MODEL.json, format tilth-cnn-segmenter/1) that tells the stage how
to prepare its input and read its output (docs/segmentation-variants.md).

A frames folder holds NNNNNN.color.png (8-bit colour) and NNNNNN.labels.png (8-bit: 0
soil, 255 residue, anything else not used). The network sees a window of the depth grid
of `width/scale` x `height/scale` px resized to `width` x `height` by area averaging, as
the stage resizes the region it segments; this file's `prepare` is that preparation, and
tests/segmentation/test_cnn_agreement.py holds the stage's to it.

Exit codes: 0 written, 1 failed, 2 bad usage, 3 PyTorch (or ONNX) missing.
"""
import argparse
import glob
import json
import math
import os
import sys

FORMAT = "tilth-cnn-segmenter/1"
OPSET = 11  # OpenCV 4.6's ONNX importer reads Conv, BatchNorm, Relu, MaxPool, Resize, Concat, Sigmoid

try:
    import numpy as np
    import torch
    import torch.nn as nn
    import torch.nn.functional as F
    import torchvision.transforms.functional as TF
    from PIL import Image
except ImportError as missing:
    if __name__ == "__main__":
        sys.stderr.write("train_cnn.py: %s: install python3-torch, python3-torchvision and "
                         "python3-onnx (tools/setup.sh)\n" % missing)
        sys.exit(3)
    raise


def double_conv(inputs, outputs, convolutions):
    layers = []
    for i in range(convolutions):
        layers += [nn.Conv2d(inputs if i == 0 else outputs, outputs, 3, padding=1, bias=False),
                   nn.BatchNorm2d(outputs), nn.ReLU(inplace=True)]
    return nn.Sequential(*layers)


class UNet(nn.Module):
    """Two poolings: 3 -> c0 -> c1 -> c2 and back, nearest upsampling and skip
    concatenations, one output channel through a sigmoid: the residue probability."""

    def __init__(self, channels):
        super().__init__()
        c0, c1, c2 = channels
        self.enc0 = double_conv(3, c0, 2)
        self.enc1 = double_conv(c0, c1, 2)
        self.bottom = double_conv(c1, c2, 2)
        self.dec1 = double_conv(c2 + c1, c1, 1)
        self.dec0 = double_conv(c1 + c0, c0, 1)
        self.head = nn.Conv2d(c0, 1, 1)
        self.pool = nn.MaxPool2d(2)
        self.up = nn.Upsample(scale_factor=2, mode="nearest")

    def forward(self, x):
        e0 = self.enc0(x)
        e1 = self.enc1(self.pool(e0))
        b = self.bottom(self.pool(e1))
        d1 = self.dec1(torch.cat([self.up(b), e1], 1))
        d0 = self.dec0(torch.cat([self.up(d1), e0], 1))
        return torch.sigmoid(self.head(d0))


def prepare(rgb, size, mean, std):
    """The network's input from an RGB window (H x W x 3 uint8 array or float tensor in
    0..255): area-averaged to `size` (width, height), scaled to 0..1, then (x - mean) /
    std per channel; 1 x 3 x height x width float32."""
    x = torch.as_tensor(np.asarray(rgb, dtype=np.float32)).permute(2, 0, 1)[None]
    x = F.interpolate(x, size=(size[1], size[0]), mode="area") / 255.0
    return (x - torch.tensor(mean).view(1, 3, 1, 1)) / torch.tensor(std).view(1, 3, 1, 1)


def read_frames(folders):
    frames = []
    for folder in folders:
        colours = sorted(glob.glob(os.path.join(folder, "*.color.png")))
        for colour in colours:
            labels = colour[:-len(".color.png")] + ".labels.png"
            rgb = np.asarray(Image.open(colour).convert("RGB"))
            label = np.asarray(Image.open(labels))
            if label.shape != rgb.shape[:2]:
                raise ValueError("%s: labels %s, colour %s (expected the same size)"
                                 % (labels, label.shape, rgb.shape[:2]))
            frames.append((torch.from_numpy(rgb.copy()).permute(2, 0, 1).float(),
                           torch.from_numpy(label.copy())))
    if not frames:
        raise ValueError("no frames (*.color.png) in %s" % ", ".join(folders))
    return frames


def statistics(frames):
    """Mean and standard deviation of each channel (0..1) over the labelled pixels, and the
    soil and residue pixel counts."""
    sums, squares, count, residue, soil = torch.zeros(3), torch.zeros(3), 0, 0, 0
    for rgb, label in frames:
        used = (label == 0) | (label == 255)
        pixels = rgb[:, used] / 255.0
        sums += pixels.double().sum(1).float()
        squares += (pixels.double() ** 2).sum(1).float()
        count += pixels.shape[1]
        residue += int((label == 255).sum())
        soil += int((label == 0).sum())
    if residue == 0 or soil == 0:
        raise ValueError("the labels have %d soil and %d residue pixels (expected both)"
                         % (soil, residue))
    mean = sums / count
    std = torch.sqrt(torch.clamp(squares / count - mean ** 2, min=1e-6))
    return mean.tolist(), std.tolist(), soil, residue


class Augmenter:
    """A random window of a random frame as the network sees it, with the looks the field
    varies in: rotation, scale, brightness, white balance and blur."""

    def __init__(self, frames, size, scale, generator):
        self.frames, self.size, self.scale, self.generator = frames, size, scale, generator

    def uniform(self, low, high):
        return low + (high - low) * float(torch.rand(1, generator=self.generator))

    def window(self):
        rgb, label = self.frames[int(torch.randint(len(self.frames), (1,),
                                                   generator=self.generator))]
        angle = self.uniform(-20, 20)
        residue = (label == 255).float()[None]
        labelled = ((label == 0) | (label == 255)).float()[None]
        rgb = TF.rotate(rgb, angle, interpolation=TF.InterpolationMode.BILINEAR)
        residue = TF.rotate(residue, angle, interpolation=TF.InterpolationMode.NEAREST)
        labelled = TF.rotate(labelled, angle, interpolation=TF.InterpolationMode.NEAREST)
        zoom = math.exp(self.uniform(math.log(0.8), math.log(1.25)))
        height, width = rgb.shape[1:]
        crop_w = min(width, int(round(self.size[0] / self.scale * zoom)))
        crop_h = min(height, int(round(self.size[1] / self.scale * zoom)))
        left = int(torch.randint(width - crop_w + 1, (1,), generator=self.generator))
        top = int(torch.randint(height - crop_h + 1, (1,), generator=self.generator))
        window = (slice(None), slice(top, top + crop_h), slice(left, left + crop_w))
        target = (self.size[1], self.size[0])
        rgb = F.interpolate(rgb[window][None], size=target, mode="area")[0]
        residue = F.interpolate(residue[window][None], size=target, mode="area")[0]
        labelled = F.interpolate(labelled[window][None], size=target, mode="area")[0]
        gain = self.uniform(0.7, 1.3) * torch.tensor([self.uniform(0.9, 1.1) for _ in range(3)])
        rgb = torch.clamp(rgb * gain.view(3, 1, 1), 0, 255)
        if self.uniform(0, 1) < 0.3:
            rgb = TF.gaussian_blur(rgb, 3, self.uniform(0.3, 1.0))
        # A pixel of the window counts when most of what it averages is labelled; its
        # target is the residue share of that.
        use = labelled > 0.5
        return rgb, torch.where(use, residue / torch.clamp(labelled, min=1e-6), 0.0), use.float()


def train(frames, args, log):
    torch.manual_seed(args.seed)
    torch.use_deterministic_algorithms(True)
    generator = torch.Generator().manual_seed(args.seed)
    mean, std, soil, residue = statistics(frames)
    size = (args.width, args.height)
    model = UNet(args.channels)
    optimiser = torch.optim.Adam(model.parameters(), lr=args.learning_rate)
    augmenter = Augmenter(frames, size, args.scale, generator)
    # Classes weighted equally: a residue pixel weighs soil / residue times a soil pixel.
    residue_weight = soil / residue
    mean_t, std_t = torch.tensor(mean).view(1, 3, 1, 1), torch.tensor(std).view(1, 3, 1, 1)
    for epoch in range(args.epochs):
        total = 0.0
        for _ in range(args.steps):
            batch = [augmenter.window() for _ in range(args.batch)]
            x = (torch.stack([b[0] for b in batch]) / 255.0 - mean_t) / std_t
            y = torch.stack([b[1] for b in batch])
            use = torch.stack([b[2] for b in batch])
            p = model(x)
            weight = use * (1 + (residue_weight - 1) * y)
            loss = (F.binary_cross_entropy(p, y, weight=weight, reduction="sum")
                    / torch.clamp(weight.sum(), min=1))
            optimiser.zero_grad()
            loss.backward()
            optimiser.step()
            total += float(loss)
        log("epoch %d/%d: loss %.4f" % (epoch + 1, args.epochs, total / args.steps))
    model.eval()
    return model, mean, std, soil, residue


def without_shared_constants(path):
    """Constant folding makes equal constants (the folded biases of a fresh network) one,
    shared through Identity nodes, which OpenCV 4.6's importer cannot read: each such node
    becomes a constant of its own."""
    import onnx
    model = onnx.load(path)
    graph = model.graph
    constants = {tensor.name: tensor for tensor in graph.initializer}
    for node in [n for n in graph.node if n.op_type == "Identity" and n.input[0] in constants]:
        copy = onnx.TensorProto()
        copy.CopyFrom(constants[node.input[0]])
        copy.name = node.output[0]
        graph.initializer.append(copy)
        graph.node.remove(node)
    onnx.save(model, path)


def export(model, args, mean, std, training):
    """Writes args.out (ONNX) and its sidecar beside it (.json instead of .onnx)."""
    dummy = torch.zeros(1, 3, args.height, args.width)
    torch.onnx.export(model, dummy, args.out, opset_version=OPSET, input_names=["rgb"],
                      output_names=["residue"], do_constant_folding=True)
    without_shared_constants(args.out)
    sidecar = {
        "format": FORMAT,
        "onnx": os.path.basename(args.out),
        "input": {"width": args.width, "height": args.height, "colour_order": "rgb",
                  "scale": 1 / 255.0, "mean": mean, "std": std, "resize": "area"},
        "window_scale": args.scale,
        "output": {"meaning": "residue probability", "threshold": args.threshold},
        "network": {"kind": "unet", "channels": list(args.channels), "opset": OPSET},
        "training": training,
    }
    with open(os.path.splitext(args.out)[0] + ".json", "w") as f:
        json.dump(sidecar, f, indent=2)
        f.write("\n")


def channels(text):
    values = [int(v) for v in text.split(",")]
    if len(values) != 3 or min(values) < 1:
        raise argparse.ArgumentTypeError("expected three channel counts, e.g. 16,32,64")
    return values


def arguments(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--frames", nargs="+", required=True, help="folders of frames")
    parser.add_argument("--out", required=True, help="the ONNX file (MODEL.onnx)")
    parser.add_argument("--width", type=int, default=84, help="network input width, px")
    parser.add_argument("--height", type=int, default=64, help="network input height, px")
    parser.add_argument("--scale", type=float, default=0.25,
                        help="network pixels per depth pixel of the windows trained on")
    parser.add_argument("--channels", type=channels, default=[16, 32, 64])
    parser.add_argument("--epochs", type=int, default=30)
    parser.add_argument("--steps", type=int, default=40, help="batches per epoch")
    parser.add_argument("--batch", type=int, default=8)
    parser.add_argument("--learning-rate", type=float, default=3e-3)
    parser.add_argument("--threshold", type=float, default=0.5)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--threads", type=int, default=0, help="0: PyTorch's default")
    parser.add_argument("--training", default="", help="text for people, kept in the sidecar")
    args = parser.parse_args(argv)
    if args.width % 4 or args.height % 4 or args.width < 8 or args.height < 8:
        parser.error("--width and --height: multiples of 4, at least 8 (two poolings)")
    if not args.out.endswith(".onnx"):
        parser.error("--out %s: expected a file name ending in .onnx" % args.out)
    return args


def main(argv):
    args = arguments(argv)
    if args.threads > 0:
        torch.set_num_threads(args.threads)

    def log(line):
        print(line, flush=True)

    try:
        import onnx  # noqa: F401  (torch.onnx.export needs it)
    except ImportError as missing:
        sys.stderr.write("train_cnn.py: %s: install python3-onnx (tools/setup.sh)\n" % missing)
        return 3
    try:
        frames = read_frames(args.frames)
        model, mean, std, soil, residue = train(frames, args, log)
        training = "%s; %d frames, %d soil and %d residue pixels, %d epochs of %d x %d, seed %d" % (
            args.training, len(frames), soil, residue, args.epochs, args.steps, args.batch,
            args.seed)
        export(model, args, mean, std, training.lstrip("; "))
    except (OSError, ValueError) as error:
        sys.stderr.write("train_cnn.py: %s\n" % error)
        return 1
    log("%s: written" % args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

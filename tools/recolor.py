#!/usr/bin/env python3
"""Copies image-folder recordings with their colour images as another camera would have
delivered them: white balance, exposure, vignetting, a gamma curve. The depth, the truth
and the calibration are linked, not copied. For probing a chain's colour robustness with
`tilth ab` (docs/accuracy.md, "Other colour responses of the camera").

    python3 tools/recolor.py SOURCE DEST STEP[+STEP...]

SOURCE is a recording (a folder with recording.json) or a folder of them; DEST is made
with the same layout. The steps apply in turn to each pixel's value v in 0..1 (8 bits /
255), per channel (per colour filter site in a Bayer mosaic), and the result is rounded
and clipped to 8 bits:
    gains=B,G,R    v * the channel's gain (a white balance, a colour cast)
    exposure=F     v * F
    vignette=F     v * (1 - F * r^2), r the distance from the centre over the half-diagonal
    grayworld      each channel scaled to the image's mean of the channels (a camera's
                   continuous auto white balance)
    srgb           the sRGB transfer curve (a camera's or a renderer's gamma encoding)
"""
import argparse
import json
import os
import sys

import cv2
import numpy as np


def srgb(v):
    v = np.clip(v, 0.0, 1.0)
    return np.where(v <= 0.0031308, 12.92 * v, 1.055 * np.power(v, 1 / 2.4) - 0.055)


class Image:
    """One colour image as floats 0..1, with per-channel gains for its layout."""

    def __init__(self, pixels, color_format):
        if color_format not in ("bgr8", "bayer_rggb8"):
            raise ValueError("colour format %s: expected bgr8 or bayer_rggb8" % color_format)
        self.v = pixels.astype(np.float64) / 255.0
        self.bayer = color_format == "bayer_rggb8"

    def per_channel(self, bgr):
        """An array of the image's shape holding each pixel's channel's value of bgr."""
        if not self.bayer:
            return np.array(bgr, dtype=np.float64).reshape(1, 1, 3)
        m = np.empty(self.v.shape)
        m[0::2, 0::2] = bgr[2]
        m[0::2, 1::2] = bgr[1]
        m[1::2, 0::2] = bgr[1]
        m[1::2, 1::2] = bgr[0]
        return m

    def channel_means(self):
        if not self.bayer:
            return self.v.reshape(-1, 3).mean(axis=0)
        green = (self.v[0::2, 1::2].mean() + self.v[1::2, 0::2].mean()) / 2
        return np.array([self.v[1::2, 1::2].mean(), green, self.v[0::2, 0::2].mean()])

    def bytes(self):
        return np.clip(np.rint(self.v * 255.0), 0, 255).astype(np.uint8)


def apply(image, step):
    name, _, value = step.partition("=")
    if name == "gains":
        gains = [float(g) for g in value.split(",")]
        if len(gains) != 3:
            raise ValueError("gains=%s: expected three gains, B,G,R" % value)
        image.v = image.v * image.per_channel(gains)
    elif name == "exposure":
        image.v = image.v * float(value)
    elif name == "vignette":
        h, w = image.v.shape[:2]
        y, x = np.mgrid[0:h, 0:w]
        r2 = ((x - (w - 1) / 2) ** 2 + (y - (h - 1) / 2) ** 2) / (((w - 1) / 2) ** 2 +
                                                                  ((h - 1) / 2) ** 2)
        falloff = 1.0 - float(value) * r2
        image.v = image.v * (falloff[..., None] if image.v.ndim == 3 else falloff)
    elif name == "grayworld" and not value:
        means = image.channel_means()
        image.v = image.v * image.per_channel(means.mean() / means)
    elif name == "srgb" and not value:
        image.v = srgb(image.v)
    else:
        raise ValueError("step '%s': expected gains=B,G,R, exposure=F, vignette=F, grayworld "
                         "or srgb" % step)


def recordings(source):
    if os.path.isfile(os.path.join(source, "recording.json")):
        return [("", source)]
    found = [(name, os.path.join(source, name)) for name in sorted(os.listdir(source))
             if os.path.isfile(os.path.join(source, name, "recording.json"))]
    if not found:
        raise ValueError("%s: neither a recording (recording.json) nor a folder of them" % source)
    return found


def recolor(source, dest, steps):
    with open(os.path.join(source, "recording.json")) as f:
        color_format = json.load(f)["color_format"]
    os.makedirs(os.path.join(dest, "color"))
    for entry in os.listdir(source):
        if entry != "color":
            os.symlink(os.path.abspath(os.path.join(source, entry)), os.path.join(dest, entry))
    for png in sorted(os.listdir(os.path.join(source, "color"))):
        pixels = cv2.imread(os.path.join(source, "color", png), cv2.IMREAD_UNCHANGED)
        if pixels is None:
            raise ValueError("%s: not an image" % os.path.join(source, "color", png))
        image = Image(pixels, color_format)
        for step in steps:
            apply(image, step)
        cv2.imwrite(os.path.join(dest, "color", png), image.bytes())


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("source")
    parser.add_argument("dest")
    parser.add_argument("steps", help="STEP[+STEP...], e.g. gains=0.6,1,0.55+srgb")
    args = parser.parse_args()
    steps = args.steps.split("+")
    try:
        for step in steps:  # refuse a bad step before writing anything
            apply(Image(np.full((2, 2, 3), 128, np.uint8), "bgr8"), step)
        if os.path.exists(args.dest):
            raise ValueError("%s exists: choose a new folder" % args.dest)
        for name, folder in recordings(args.source):
            recolor(folder, os.path.join(args.dest, name), steps)
    except (ValueError, OSError) as error:
        print("recolor.py: %s" % error, file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())

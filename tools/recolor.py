#!/usr/bin/env python3
"""Copies image-folder recordings with their colour images as another camera would have
delivered them: white balance, exposure, vignetting, a gamma curve. The depth, the truth
and the calibration are linked, not copied. For probing a chain's colour robustness with
`tilth ab` (docs/accuracy.md, "Other colour responses of the camera").

    python3 tools/recolor.py SOURCE DEST STEP[+STEP...]

SOURCE is a recording (a folder with recording.json) or a folder of them; DEST is made
with the same layout; on an error it is removed again. Colour formats: bgr8 and the four
bayer_*8 mosaics. The steps apply in turn to each pixel's value v in 0..1 (8 bits / 255),
per channel (per colour filter site in a mosaic), and the result is rounded and clipped
to 8 bits:
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
import shutil
import sys

import cv2
import numpy as np


def srgb(v):
    v = np.clip(v, 0.0, 1.0)
    return np.where(v <= 0.0031308, 12.92 * v, 1.055 * np.power(v, 1 / 2.4) - 0.055)


# The colour at each site of a Bayer tile, (0,0) (0,1) (1,0) (1,1), as B, G, R = 0, 1, 2.
BAYER_TILES = {"bayer_rggb8": (2, 1, 1, 0), "bayer_bggr8": (0, 1, 1, 2),
               "bayer_grbg8": (1, 2, 0, 1), "bayer_gbrg8": (1, 0, 2, 1)}
FORMATS = ["bgr8", *BAYER_TILES]


class Image:
    """One colour image as floats 0..1 (`values`), with per-channel gains for its layout."""

    def __init__(self, pixels, color_format):
        self.values = pixels.astype(np.float64) / 255.0
        self.tile = BAYER_TILES.get(color_format)

    def sites(self):
        """(rows, cols, channel) of each site of the Bayer tile."""
        return [(rows, cols, self.tile[2 * rows + cols]) for rows in (0, 1) for cols in (0, 1)]

    def per_channel(self, bgr):
        """An array of the image's shape holding each pixel's channel's value of bgr."""
        if self.tile is None:
            return np.array(bgr, dtype=np.float64).reshape(1, 1, 3)
        gains = np.empty(self.values.shape)
        for rows, cols, channel in self.sites():
            gains[rows::2, cols::2] = bgr[channel]
        return gains

    def channel_means(self):
        if self.tile is None:
            return self.values.reshape(-1, 3).mean(axis=0)
        sums, counts = np.zeros(3), np.zeros(3)
        for rows, cols, channel in self.sites():
            site = self.values[rows::2, cols::2]
            sums[channel] += site.sum()
            counts[channel] += site.size
        return sums / counts

    def bytes(self):
        return np.clip(np.rint(self.values * 255.0), 0, 255).astype(np.uint8)


def number(step, value):
    try:
        return float(value)
    except ValueError:
        raise ValueError("step '%s': expected a number after '='" % step) from None


def apply(image, step):
    name, _, value = step.partition("=")
    if name == "gains":
        gains = value.split(",")
        if len(gains) != 3:
            raise ValueError("step '%s': expected three gains, B,G,R" % step)
        image.values = image.values * image.per_channel([number(step, g) for g in gains])
    elif name == "exposure":
        image.values = image.values * number(step, value)
    elif name == "vignette":
        h, w = image.values.shape[:2]
        y, x = np.mgrid[0:h, 0:w]
        r2 = ((x - (w - 1) / 2) ** 2 + (y - (h - 1) / 2) ** 2) / (((w - 1) / 2) ** 2 +
                                                                  ((h - 1) / 2) ** 2)
        falloff = 1.0 - number(step, value) * r2
        image.values = image.values * (falloff[..., None] if image.values.ndim == 3 else falloff)
    elif name == "grayworld" and not value:
        means = image.channel_means()
        lit = means > 0  # a black channel stays black
        gains = np.ones(3)
        gains[lit] = means[lit].mean() / means[lit]
        image.values = image.values * image.per_channel(gains)
    elif name == "srgb" and not value:
        image.values = srgb(image.values)
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


def color_format(recording):
    with open(os.path.join(recording, "recording.json")) as f:
        found = json.load(f).get("color_format")
    if found not in FORMATS:
        raise ValueError("%s: colour format %s, expected one of %s"
                         % (recording, found, ", ".join(FORMATS)))
    return found


def recolor(source, dest, layout, steps):
    entries = os.listdir(source)
    os.makedirs(os.path.join(dest, "color"))
    for entry in entries:
        if entry != "color":
            os.symlink(os.path.abspath(os.path.join(source, entry)), os.path.join(dest, entry))
    for png in sorted(os.listdir(os.path.join(source, "color"))):
        path = os.path.join(source, "color", png)
        pixels = cv2.imread(path, cv2.IMREAD_UNCHANGED)
        if pixels is None:
            raise ValueError("%s: not an image" % path)
        image = Image(pixels, layout)
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
        found = [(name, folder, color_format(folder))
                 for name, folder in recordings(args.source)]
    except (ValueError, OSError) as error:
        print("recolor.py: %s" % error, file=sys.stderr)
        return 2
    try:
        for name, folder, layout in found:
            recolor(folder, os.path.join(args.dest, name), layout, steps)
    except (ValueError, OSError) as error:
        shutil.rmtree(args.dest, ignore_errors=True)  # made here: nothing of the user's
        print("recolor.py: %s (%s removed)" % (error, args.dest), file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""tools/recolor.py against values computed here: a colour cast, exposure and the sRGB
curve on a bgr8 and a Bayer recording made by `tilth simulate`; depth and truth linked,
not copied; a BGGR mosaic's sites; a bad step or an existing destination refused before
anything is written, and an unreadable image leaving no destination behind."""
import json
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

import cv2
import numpy as np

TILTH = os.environ["TILTH_BIN"]
RECOLOR = os.path.join(os.environ["TILTH_SOURCE_DIR"], "tools", "recolor.py")


def recolor(*args):
    return subprocess.run([sys.executable, RECOLOR, *args], capture_output=True, text=True,
                          timeout=120)


def srgb(v):
    return np.where(v <= 0.0031308, 12.92 * v, 1.055 * np.power(v, 1 / 2.4) - 0.055)


class Recolor(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="tilth-recolor-")
        cls.source = os.path.join(cls.tmp, "source")
        for name, color_format in (("bgr", "bgr8"), ("bayer", "bayer_rggb8")):
            result = subprocess.run(
                [TILTH, "simulate", os.path.join(cls.source, name), "--preset", "case_c",
                 "--frames", "1", "--color-format", color_format],
                capture_output=True, text=True, timeout=300)
            assert result.returncode == 0, result.stderr[-2000:]
        cls.dest = os.path.join(cls.tmp, "warm")
        result = recolor(cls.source, cls.dest, "gains=0.5,1,1.5+exposure=1.2+srgb")
        assert result.returncode == 0, result.stderr

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def images(self, name):
        path = os.path.join(name, "color", "000000.png")
        before = cv2.imread(os.path.join(self.source, path), cv2.IMREAD_UNCHANGED)
        after = cv2.imread(os.path.join(self.dest, path), cv2.IMREAD_UNCHANGED)
        return before.astype(np.float64) / 255.0, after

    def expected(self, v, gain):
        return np.clip(np.rint(srgb(np.clip(v * gain * 1.2, 0, 1)) * 255), 0, 255)

    def test_each_channel_of_a_bgr_image_is_cast_exposed_and_gamma_encoded(self):
        before, after = self.images("bgr")
        self.assertEqual(after.shape, before.shape)
        for channel, gain in enumerate((0.5, 1.0, 1.5)):
            np.testing.assert_array_equal(after[..., channel],
                                          self.expected(before[..., channel], gain))

    def test_each_site_of_a_bayer_mosaic_takes_its_filter_colours_gain(self):
        before, after = self.images("bayer")
        for rows, cols, gain in ((0, 0, 1.5), (0, 1, 1.0), (1, 0, 1.0), (1, 1, 0.5)):  # RGGB
            np.testing.assert_array_equal(after[rows::2, cols::2],
                                          self.expected(before[rows::2, cols::2], gain))

    def test_a_bggr_mosaic_has_blue_where_rggb_has_red(self):
        bggr = os.path.join(self.tmp, "bggr")
        shutil.copytree(os.path.join(self.source, "bayer"), bggr)
        with open(os.path.join(bggr, "recording.json")) as f:
            recording = json.load(f)
        recording["color_format"] = "bayer_bggr8"
        with open(os.path.join(bggr, "recording.json"), "w") as f:
            json.dump(recording, f)
        dest = os.path.join(self.tmp, "bggr-blue")
        self.assertEqual(recolor(bggr, dest, "gains=2,1,1").returncode, 0)
        before = cv2.imread(os.path.join(bggr, "color", "000000.png"), cv2.IMREAD_UNCHANGED)
        after = cv2.imread(os.path.join(dest, "color", "000000.png"), cv2.IMREAD_UNCHANGED)
        np.testing.assert_array_equal(after[0::2, 0::2],
                                      np.clip(before[0::2, 0::2].astype(int) * 2, 0, 255))
        np.testing.assert_array_equal(after[1::2, 1::2], before[1::2, 1::2])

    def test_an_unreadable_image_leaves_no_destination(self):
        broken = os.path.join(self.tmp, "broken")
        shutil.copytree(os.path.join(self.source, "bgr"), broken)
        with open(os.path.join(broken, "color", "000001.png"), "w") as f:
            f.write("not a png")
        dest = os.path.join(self.tmp, "broken-warm")
        result = recolor(broken, dest, "srgb")
        self.assertEqual(result.returncode, 2)
        self.assertIn("000001.png: not an image", result.stderr)
        self.assertFalse(os.path.exists(dest))

    def test_depth_truth_and_calibration_are_the_sources(self):
        for entry in ("depth", "mask", "recording.json", "rig.calib.json"):
            path = os.path.join(self.dest, "bgr", entry)
            self.assertTrue(os.path.islink(path), path)
            self.assertEqual(os.path.realpath(path),
                             os.path.realpath(os.path.join(self.source, "bgr", entry)))

    def test_a_bad_step_is_refused_naming_it_and_writes_nothing(self):
        dest = os.path.join(self.tmp, "bad")
        result = recolor(self.source, dest, "gains=1,1+srgb")
        self.assertEqual(result.returncode, 2)
        self.assertIn("step 'gains=1,1': expected three gains", result.stderr)
        self.assertFalse(os.path.exists(dest))
        result = recolor(self.source, self.dest, "srgb")
        self.assertEqual(result.returncode, 2)
        self.assertIn("exists", result.stderr)


if __name__ == "__main__":
    unittest.main()

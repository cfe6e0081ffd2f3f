"""Inputs that once gave wrong distances served as valid (issue #14, finding 1), replayed
through graphs/paper.json (the measurement chain every machine graph shares): a depth
image of noise (once 423 mm valid), a saturated depth image (1440.7 mm valid), an
all-white and an all-black colour image (517.3 mm valid, all residue taken for soil).
Every frame of each must reach the CSV invalid, with the cause the plausibility gates
give; the untouched recording stays valid and within a millimetre of its truth, so the
gates are not simply refusing everything.
"""
import csv
import os
import shutil
import subprocess
import tempfile
import unittest

import cv2
import numpy as np

TILTH = os.environ["TILTH_BIN"]
GRAPHS = os.path.join(os.environ["TILTH_SOURCE_DIR"], "graphs")
FRAMES = 3


def run_paper_chain(recording, out_csv):
    result = subprocess.run(
        [TILTH, "run", os.path.join(GRAPHS, "paper.json"), "--quiet",
         "--set", "input.path=" + recording, "--set", "output.path=" + out_csv],
        capture_output=True, text=True, timeout=120)
    if result.returncode != 0:
        raise AssertionError("tilth run failed (%d): %s" % (result.returncode, result.stderr[-2000:]))
    with open(out_csv) as f:
        return list(csv.DictReader(f))


def replace_images(recording, folder, make):
    """Every image in recording/folder replaced by make(original image)."""
    directory = os.path.join(recording, folder)
    for name in sorted(os.listdir(directory)):
        path = os.path.join(directory, name)
        original = cv2.imread(path, cv2.IMREAD_UNCHANGED)
        assert cv2.imwrite(path, make(original)), path


class ImplausibleInputs(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="tilth-implausible-")
        cls.clean = os.path.join(cls.tmp, "clean")
        result = subprocess.run(
            [TILTH, "simulate", cls.clean, "--preset", "case_c", "--frames", str(FRAMES)],
            capture_output=True, text=True, timeout=300)
        assert result.returncode == 0, result.stderr[-2000:]

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def variant(self, name, folder, make):
        recording = os.path.join(self.tmp, name)
        shutil.copytree(self.clean, recording)
        replace_images(recording, folder, make)
        return run_paper_chain(recording, os.path.join(self.tmp, name + ".csv"))

    def assert_all_invalid(self, rows, cause):
        self.assertEqual(len(rows), FRAMES)
        for row in rows:
            self.assertEqual((row["valid"], row["distance_mm"], row["cause"]), ("0", "nan", cause),
                             row)

    def test_the_untouched_recording_is_valid_and_close_to_its_truth(self):
        rows = run_paper_chain(self.clean, os.path.join(self.tmp, "clean.csv"))
        self.assertEqual(len(rows), FRAMES)
        for row in rows:
            self.assertEqual(row["valid"], "1", row)
            self.assertLess(abs(float(row["distance_mm"]) - float(row["truth_mm"])), 1.0, row)

    def test_a_depth_image_of_noise_has_no_soil_surface(self):
        # Nearly every pixel stands more than height_mm above the envelope of its
        # neighbours: residue by height, so too little is left for soil.
        rng = np.random.default_rng(14)
        rows = self.variant("noise", "depth",
                            lambda image: rng.integers(1, 65535, image.shape, dtype=np.uint16))
        self.assert_all_invalid(rows, "too_little_soil")

    def test_a_saturated_depth_image_has_no_soil(self):
        rows = self.variant("saturated", "depth", lambda image: np.full_like(image, 65535))
        self.assert_all_invalid(rows, "too_little_soil")

    def test_an_all_white_colour_image_is_unusable(self):
        rows = self.variant("white", "color", lambda image: np.full_like(image, 255))
        self.assert_all_invalid(rows, "image_unusable")

    def test_an_all_black_colour_image_is_unusable(self):
        rows = self.variant("black", "color", lambda image: np.zeros_like(image))
        self.assert_all_invalid(rows, "image_unusable")


if __name__ == "__main__":
    unittest.main()

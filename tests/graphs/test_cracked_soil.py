"""Cracked clay (issue #15).

Dry clay's cracks show soil 10-20 mm beyond the ground on every side of the tool, as
straw taken for soil does (preset cracked, the field rig's Bayer camera). The shipped
chain measures the clods' surface, and the plausibility gate "soil beyond the ground on
every side" (docs/estimation.md) must leave every frame valid and within issue #15's
1.5 mm. With the gate at 2 % of the soil, its first setting, some of these frames were
invalid for it, so the test can fail.

Under heavy cover (cracked_cover, seed 3) the soil near the tool point of the first frame
is a crack's slope, and the ground fitted on its level read 3.5 mm far, valid. The tool's
surface now has to hold most of the soil around the tool (min_surrounding_fraction): that
frame is invalid, and without the rule it is the wrong valid distance again.
"""
import os
import shutil
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                                "support"))
from simulated_ab import compare, frames_of, simulate  # noqa: E402

TILTH = os.environ["TILTH_BIN"]
SOURCE = os.environ["TILTH_SOURCE_DIR"]
FRAMES = 4
SOIL_BEYOND = "soil beyond the ground measured on every side"


class CrackedSoil(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="tilth-cracked-soil-")
        recording = simulate(
            TILTH, os.path.join(cls.tmp, "cracked"), "cracked", "--frames", str(FRAMES),
            "--calibration", os.path.join(SOURCE, "calib", "field_rig.calib.json"),
            "--color-format", "bayer_rggb8")
        cls.report = compare(TILTH, recording, os.path.join(cls.tmp, "report"), "shipped",
                             "at_2_percent:estimate.max_soil_beyond=0.02")

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def test_every_frame_is_valid_and_within_the_bounds(self):
        frames = frames_of(self.report, "shipped", "cracked")
        self.assertEqual(len(frames), FRAMES)
        for frame in frames:
            self.assertTrue(frame["valid"], frame["invalid_reason"])
            self.assertLess(abs(frame["distance_mm"] - frame["truth_mm"]), 1.5, frame)

    def test_at_two_percent_the_cracks_looked_like_residue_taken_for_soil(self):
        reasons = [frame["invalid_reason"] for frame in frames_of(self.report, "at_2_percent", "cracked")]
        self.assertTrue(any(reason.startswith(SOIL_BEYOND) for reason in reasons), reasons)


class ACrackUnderTheTool(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="tilth-crack-under-the-tool-")
        recording = simulate(TILTH, os.path.join(cls.tmp, "cracked_cover"), "cracked_cover",
                             "--frames", "1", "--seed", "3")
        cls.report = compare(TILTH, recording, os.path.join(cls.tmp, "report"), "shipped",
                             "unchecked:estimate.min_surrounding_fraction=0")

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def test_the_cracks_level_is_not_the_ground(self):
        [frame] = frames_of(self.report, "shipped", "cracked_cover")
        self.assertFalse(frame["valid"])
        self.assertTrue(frame["invalid_reason"].startswith(
            "the tool's surface holds too little of the soil around it"), frame)

    def test_without_the_rule_the_crack_is_measured(self):
        [frame] = frames_of(self.report, "unchecked", "cracked_cover")
        self.assertTrue(frame["valid"], frame["invalid_reason"])
        self.assertGreater(frame["distance_mm"] - frame["truth_mm"], 1.5)


if __name__ == "__main__":
    unittest.main()

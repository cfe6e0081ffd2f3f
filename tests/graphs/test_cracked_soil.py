"""Cracked clay (issue #15): dry clay's cracks show soil 10-20 mm beyond the ground on every
side of the tool, as straw taken for soil does (preset cracked, the field rig's Bayer
camera). The shipped chain measures the clods' surface, and the plausibility gate "soil
beyond the ground on every side" (docs/estimation.md) must leave every frame valid and
within issue #15's 1.5 mm. With the gate at 2 % of the soil, its first setting, some of
these frames were invalid for it, so the test can fail.
"""
import json
import os
import shutil
import subprocess
import tempfile
import unittest

TILTH = os.environ["TILTH_BIN"]
SOURCE = os.environ["TILTH_SOURCE_DIR"]
FRAMES = 4
SOIL_BEYOND = "soil beyond the ground measured on every side"


def frames_of(report, variant):
    path = os.path.join(report, "runs", variant, "cracked", "frames.jsonl")
    with open(path) as f:
        return [json.loads(line) for line in f]


class CrackedSoil(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="tilth-cracked-soil-")
        recording = os.path.join(cls.tmp, "cracked")
        result = subprocess.run(
            [TILTH, "simulate", recording, "--preset", "cracked", "--frames", str(FRAMES),
             "--calibration", os.path.join(SOURCE, "calib", "field_rig.calib.json"),
             "--color-format", "bayer_rggb8"],
            capture_output=True, text=True, timeout=300)
        assert result.returncode == 0, result.stderr[-2000:]
        cls.report = os.path.join(cls.tmp, "report")
        result = subprocess.run(
            [TILTH, "ab", recording, "--out", cls.report, "--overlays", "0", "--quiet",
             "--variant", "shipped",
             "--variant", "at_2_percent:estimate.max_soil_beyond=0.02"],
            capture_output=True, text=True, timeout=300)
        assert result.returncode == 0, result.stderr[-2000:]

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def test_every_frame_is_valid_and_within_the_bounds(self):
        frames = frames_of(self.report, "shipped")
        self.assertEqual(len(frames), FRAMES)
        for frame in frames:
            self.assertTrue(frame["valid"], frame["invalid_reason"])
            self.assertLess(abs(frame["distance_mm"] - frame["truth_mm"]), 1.5, frame)

    def test_at_two_percent_the_cracks_looked_like_residue_taken_for_soil(self):
        reasons = [frame["invalid_reason"] for frame in frames_of(self.report, "at_2_percent")]
        self.assertTrue(any(reason.startswith(SOIL_BEYOND) for reason in reasons), reasons)


if __name__ == "__main__":
    unittest.main()

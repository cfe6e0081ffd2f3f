"""`tilth train-segmenter --labels depth` from the command line, on simulated recordings:
it trains on a recording without a mask column and says that it cannot score it, scores a
recording with a mask against that mask, and stops with a message naming what is wrong
for an unknown --labels, options of depth labels without them, margins that leave no band
between soil and residue, and a recording whose frames give no pixel a depth label. How
well the labels agree with the truth and teach is pinned in
tests/segmentation/depth_labels_test.cpp.
"""
import csv
import json
import os
import shutil
import struct
import sys
import tempfile
import unittest
import zlib

SUPPORT = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "support")
sys.path.insert(0, SUPPORT)
from processes import run_bounded  # noqa: E402

TILTH = os.environ["TILTH_BIN"]


def write_blank_depth_png(path, width, height):
    """A 16-bit grey PNG of zeros: raw ToF gray 0, "no data" in every pixel."""
    def chunk(kind, data):
        return (struct.pack(">I", len(data)) + kind + data
                + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))
    rows = b"".join(b"\x00" + bytes(2 * width) for _ in range(height))
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n"
                + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 16, 0, 0, 0, 0))
                + chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b""))


def drop_mask_column(recording):
    """The recording as one without masks: no `mask` column in frames.csv, no mask/."""
    path = os.path.join(recording, "frames.csv")
    with open(path) as f:
        rows = list(csv.DictReader(f))
    columns = [c for c in rows[0] if c != "mask"]
    with open(path, "w", newline="") as f:
        writer = csv.DictWriter(f, columns, extrasaction="ignore", lineterminator="\n")
        writer.writeheader()
        writer.writerows(rows)
    shutil.rmtree(os.path.join(recording, "mask"))


class DepthLabels(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="tilth-depth-labels-")
        cls.masked = os.path.join(cls.tmp, "case_c")
        cls.unmasked = os.path.join(cls.tmp, "field")
        cls.no_depth = os.path.join(cls.tmp, "no_depth")
        for recording, preset, frames in ((cls.masked, "case_c", 2), (cls.unmasked, "field", 2),
                                          (cls.no_depth, "flat", 1)):
            cls.tilth_ok("simulate", recording, "--preset", preset, "--frames", str(frames))
        drop_mask_column(cls.unmasked)
        for name in os.listdir(os.path.join(cls.no_depth, "depth")):
            write_blank_depth_png(os.path.join(cls.no_depth, "depth", name), 640, 480)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    @classmethod
    def tilth(cls, *arguments):
        return run_bounded([TILTH, *arguments], cls.tmp, seconds=300)

    @classmethod
    def tilth_ok(cls, *arguments):
        done = cls.tilth(*arguments)
        if done.returncode != 0:
            raise AssertionError("tilth %s failed (%d): %s"
                                 % (" ".join(arguments), done.returncode, done.stderr[-4000:]))
        return done

    def model(self):
        return os.path.join(self.tmp, "model.yml.gz")

    def test_trains_on_a_recording_without_masks_and_scores_where_there_is_one(self):
        report = os.path.join(self.tmp, "report.json")
        done = self.tilth_ok("train-segmenter", self.masked, self.unmasked, "--labels", "depth",
                             "--out", self.model(), "--report", report)
        lines = done.stdout.splitlines()
        # Measured: 79.9 % of case C's trusted pixels labelled, 99.97 % of them as its mask
        # says; 60.4 % of the field's.
        self.assertRegex(lines[0], r"^%s: 2 frames for training, 0 held out, depth labels "
                         r"7\d\.\d\d %% of its pixels with trusted colour \(soil \d+\.\d\d %%, "
                         r"residue \d+\.\d\d %%\); they agree with its mask on 99\.9\d %% of the "
                         r"\d+ pixels both label$" % self.masked)
        self.assertRegex(lines[1], r"^%s: 2 frames for training, 0 held out, depth labels "
                         r"\d+\.\d\d %% of its pixels with trusted colour \(soil \d+\.\d\d %%, "
                         r"residue \d+\.\d\d %%\); it has no mask to compare them with$"
                         % self.unmasked)
        self.assertRegex(done.stdout, r"\n  %s +no mask to score against\n" % self.unmasked)
        self.assertIn("\n  mean IoU of the recordings scored (1 of 2): 0.9", done.stdout)
        with open(report) as f:
            scores = json.load(f)
        self.assertEqual(scores["labels"], "depth")
        self.assertEqual(scores["depth_labels"], {"soil_within_mm": 1.5, "residue_above_mm": 4.0,
                                                  "edge_px": 1, "envelope_px": 0.0})
        rows = {row["recording"]: row for row in scores["recordings"]}
        self.assertEqual(rows[self.unmasked], {"recording": self.unmasked, "scored": False,
                                               "trained_on": [self.masked]})
        # Case C scored by a model that saw only the field's depth labels (0.968 measured with
        # the field's mask in its recording: the mask played no part in training).
        self.assertTrue(rows[self.masked]["scored"])
        self.assertGreater(rows[self.masked]["iou"], 0.93)
        self.assertEqual(scores["overall"]["iou"], rows[self.masked]["iou"])
        self.assertTrue(os.path.exists(self.model()))

    def assert_usage_error(self, message, *options):
        done = self.tilth("train-segmenter", self.masked, "--out", self.model(), *options)
        self.assertEqual(done.returncode, 2, done.stderr)
        self.assertEqual(done.stderr.splitlines()[0], "tilth train-segmenter: " + message)

    def test_unknown_labels(self):
        self.assert_usage_error('--labels "hand" (expected mask or depth)', "--labels", "hand")

    def test_depth_label_options_without_depth_labels(self):
        self.assert_usage_error("--soil-within-mm is an option of --labels depth (labels: mask)",
                                "--soil-within-mm", "2")

    def test_margins_without_a_band_between_soil_and_residue(self):
        self.assert_usage_error(
            "depth labels of soil within 4 mm, residue above 3 mm, edge 1 px, "
            "envelope 0 px (expected residue above the soil band: residue above > soil "
            "within)", "--labels", "depth", "--soil-within-mm", "4", "--residue-above-mm", "3")

    def test_a_recording_without_labelable_pixels_is_named(self):
        done = self.tilth("train-segmenter", self.masked, self.no_depth, "--labels", "depth",
                          "--out", self.model())
        self.assertEqual(done.returncode, 1, done.stderr)
        self.assertEqual(done.stderr.strip(),
                         "tilth train-segmenter: recording '%s': depth labels no pixel of its 1 "
                         "training frames (0 of their pixels have trusted colour; expected pixels "
                         "with depth, soil within 1.5 mm of the surface fitted to it or residue "
                         "more than 4 mm above it)" % self.no_depth)


if __name__ == "__main__":
    unittest.main()

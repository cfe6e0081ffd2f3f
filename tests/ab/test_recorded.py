"""A recorded variant (`--variant live:recorded`): what the machine measured, recorded
beside the frames by mcap.writer, judged against the truth as a variant is. A live run
is made here (synthetic.scene -> the measurement chain -> mcap.writer with the chain's
distance), then `tilth ab` compares it with the chain replayed on the same frames: the
same input gives the same distances, frame for frame, so every difference is 0. Also
the mistakes: a recorded variant on an image folder or on an MCAP file without the
distance, and a recorded variant with settings."""
import csv
import json
import os
import shutil
import subprocess
import tempfile
import unittest

from make_fixture import CALIBRATION, FIXTURE, SOURCE, TILTH

FRAMES = 4


def run(command):
    return subprocess.run(command, capture_output=True, text=True, timeout=150)


class RecordedVariantTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.folder = tempfile.mkdtemp(prefix="tilth-ab-recorded-")
        cls.mcap = os.path.join(cls.folder, "field-7.mcap")
        cls.live_csv = os.path.join(cls.folder, "live.csv")
        graph = {
            "include": [{"file": os.path.join(SOURCE, "graphs", "measurement-chain.json"),
                         "as": "chain", "variables": {"calibration": CALIBRATION}}],
            "nodes": {
                "scene": {"type": "synthetic.scene",
                          "params": {"calibration": CALIBRATION, "preset": "case_c",
                                     "frames": FRAMES}},
                "record": {"type": "mcap.writer",
                           "params": {"path": cls.mcap, "calibration": CALIBRATION,
                                      "when_behind": "wait"}},
                "log": {"type": "sinks.csv", "params": {"path": cls.live_csv}}},
            "edges": [["scene.raw", "chain/project.raw"], ["scene.color", "chain/register.color"],
                      ["scene.raw", "record.raw"], ["scene.color", "record.color"],
                      ["scene.truth", "record.truth"],
                      ["chain/estimate.distance", "record.distance"],
                      ["chain/estimate.distance", "log.distance"]]}
        with open(os.path.join(cls.folder, "live.json"), "w") as f:
            json.dump(graph, f)
        result = run([TILTH, "run", os.path.join(cls.folder, "live.json"), "--quiet"])
        assert result.returncode == 0, result.stderr
        cls.out = os.path.join(cls.folder, "ab")
        cls.result = run([TILTH, "ab", cls.mcap, "--variant", "live:recorded",
                          "--variant", "replayed", "--var", "calibration=" + CALIBRATION,
                          "--overlays", "0", "--out", cls.out, "--quiet"])

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.folder)

    def frames(self, variant):
        with open(os.path.join(self.out, "frames.csv")) as f:
            return [row for row in csv.DictReader(f) if row["variant"] == variant]

    def test_the_recorded_distances_are_judged_as_a_variant(self):
        self.assertEqual(self.result.returncode, 0, self.result.stderr)
        with open(self.live_csv) as f:
            live = list(csv.DictReader(f))
        recorded = self.frames("live")
        self.assertEqual([int(r["frame_id"]) for r in recorded], [int(r["index"]) for r in live])
        for row, logged in zip(recorded, live):
            self.assertEqual(row["valid"], logged["valid"])
            self.assertAlmostEqual(float(row["distance_mm"]), float(logged["distance_mm"]),
                                   delta=0.0005)  # the csv sink's 3 decimals
            self.assertAlmostEqual(float(row["error_mm"]),
                                   float(row["distance_mm"]) - float(row["truth_mm"]), delta=1e-9)

    def test_the_same_frames_replayed_give_the_same_distances(self):
        recorded, replayed = self.frames("live"), self.frames("replayed")
        self.assertEqual(len(recorded), FRAMES)
        for a, b in zip(recorded, replayed):
            self.assertEqual((a["frame_id"], a["valid"], a["distance_mm"]),
                             (b["frame_id"], b["valid"], b["distance_mm"]))
        with open(os.path.join(self.out, "summary.json")) as f:
            summary = json.load(f)
        variants = {v["name"]: v for v in summary["variants"]}
        self.assertTrue(variants["live"]["recorded"])
        self.assertFalse(variants["replayed"]["recorded"])
        against = {v["variant"]: v["against_baseline"] for v in summary["variant_figures"]}
        self.assertEqual(against["replayed"]["abs_error_difference_mm"], 0.0)
        self.assertEqual(against["replayed"]["frames_with_both_error_values"], FRAMES)

    def assert_refused(self, arguments, message):
        result = run([TILTH, "ab", *arguments, "--out", os.path.join(self.folder, "refused"),
                      "--quiet"])
        self.assertEqual(result.returncode, 2, result.stderr)
        self.assertIn(message, result.stderr)

    def test_recordings_without_what_was_measured_are_refused(self):
        folder = os.path.join(FIXTURE, "recordings", "case_c")
        self.assert_refused([folder, "--variant", "live:recorded"],
                            "variant 'live' is what the machine measured, and " + folder +
                            " does not hold it: only MCAP recordings do (docs/mcap.md)")
        mcap = os.path.join(FIXTURE, "recordings", "case_c_mcap.mcap")
        self.assert_refused([mcap, "--variant", "live:recorded"],
                            mcap + " does not hold it: no /tilth/distance channel (recorded "
                            "without mcap.writer's distance input)")

    def test_a_recorded_variant_takes_no_settings(self):
        self.assert_refused([self.mcap, "--variant", "live:recorded",
                             "--variant", "live:segment.dilation_px=2"],
                            "variant 'live' is recorded: it runs no chain, so it takes no "
                            "settings")


if __name__ == "__main__":
    unittest.main()

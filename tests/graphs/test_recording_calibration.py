"""A replay uses the calibration of the rig that made the recording, with no flag (issue
#14, finding 3; issue #15): two rigs that differ only in their extrinsics (the paper's,
and tests/graphs/moved_rig.calib.json: the colour camera 83 mm away on the other side,
turned by 0.6 and 0.8 degrees). A recording of the moved rig, replayed through
graphs/paper.json as it ships (whose default names no calibration), measures within a
millimetre of its truth, as an image folder and as MCAP. Naming the paper's rig with
--var calibration overrides the recording's, and never silently: a warning names each
field that differs.
"""
import csv
import json
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

SUPPORT = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "support")
sys.path.insert(0, SUPPORT)
from rigs import paper_rig_path  # noqa: E402

TILTH = os.environ["TILTH_BIN"]
SOURCE = os.environ["TILTH_SOURCE_DIR"]
PAPER = os.path.join(SOURCE, "graphs", "paper.json")
MOVED_RIG = os.path.join(SOURCE, "tests", "graphs", "moved_rig.calib.json")
PAPER_RIG = paper_rig_path()
FRAMES = 3


def tilth(*args, timeout=300):
    return subprocess.run([TILTH, *args], capture_output=True, text=True, timeout=timeout)


class RecordingCalibration(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="tilth-rig-")
        cls.folder = os.path.join(cls.tmp, "moved")
        cls.mcap = os.path.join(cls.tmp, "moved.mcap")
        for out in (cls.folder, cls.mcap):
            result = tilth("simulate", out, "--preset", "case_c", "--frames", str(FRAMES),
                           "--calibration", MOVED_RIG)
            assert result.returncode == 0, result.stderr[-2000:]

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def replay(self, name, *options, graph=PAPER):
        out = os.path.join(self.tmp, name + ".csv")
        result = tilth("run", graph, "--quiet", "--set", "output.path=" + out, *options)
        self.assertEqual(result.returncode, 0, result.stderr[-2000:])
        with open(out) as f:
            return list(csv.DictReader(f)), result.stderr

    def assert_within_a_millimetre(self, rows):
        self.assertEqual(len(rows), FRAMES)
        for row in rows:
            self.assertEqual(row["valid"], "1", row)
            self.assertLess(abs(float(row["distance_mm"]) - float(row["truth_mm"])), 1.0, row)

    def test_an_image_folder_is_replayed_with_its_own_rig(self):
        rows, log = self.replay("folder", "--set", "input.path=" + self.folder)
        self.assert_within_a_millimetre(rows)
        self.assertNotIn("overrides", log)

    def test_an_mcap_recording_is_replayed_with_its_own_rig(self):
        graph = os.path.join(self.tmp, "paper-mcap.json")
        with open(graph, "w") as f:
            json.dump({"include": [PAPER],
                       "nodes": {"input": {"type": "mcap.player", "params": {"path": self.mcap}}}},
                      f)
        rows, log = self.replay("mcap", graph=graph)
        self.assert_within_a_millimetre(rows)
        self.assertNotIn("overrides", log)

    def test_another_rig_named_explicitly_overrides_it_loudly(self):
        _, log = self.replay("overridden", "--set", "input.path=" + self.folder,
                             "--var", "calibration=" + PAPER_RIG)
        self.assertIn("parameter 'calibration' (%s) overrides the calibration the frames carry "
                      "(%s)" % (PAPER_RIG, os.path.join(self.folder, "rig.calib.json")), log)
        for field in ("/depth_to_color/R/0/0", "/depth_to_color/T_mm/0: 45.0 against -38.0",
                      "/depth_to_color/T_mm/1: 0.0 against 12.0"):
            self.assertIn(field, log)
        self.assertNotIn("/depth_camera", log)  # the intrinsics are the same
        self.assertNotIn("/color_camera", log)

    def test_the_same_rig_named_explicitly_is_no_override(self):
        _, log = self.replay("same", "--set", "input.path=" + self.folder,
                             "--var", "calibration=" + MOVED_RIG)
        self.assertNotIn("overrides", log)


if __name__ == "__main__":
    unittest.main()

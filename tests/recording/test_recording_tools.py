"""`tilth simulate` and `tilth recording`, run as a user runs them: what the options do,
what the outputs hold (read by check_folder.py's own PNG decoder and by numpy, not by
Tilth), and the message and exit code of each kind of bad input. The round trip through
both formats is tests/mcap/js/round_trip.test.mjs."""
import csv
import json
import os
import re
import subprocess
import sys
import tempfile
import time
import unittest

import numpy as np

from check_folder import PNG_GRAY, PNG_RGB, make_frames, read_png, small_calibration, \
    write_input_recording

SUPPORT = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "support")
sys.path.insert(0, SUPPORT)
from rigs import paper_rig_path, quarter_rig  # noqa: E402

TILTH = os.environ["TILTH_BIN"]
MCAP_MAGIC = b"\x89MCAP0\r\n"


def tilth(*args, timeout=120):
    return subprocess.run([TILTH, *map(str, args)], capture_output=True, text=True,
                          timeout=timeout)


def frames_csv(folder):
    with open(os.path.join(folder, "frames.csv"), newline="") as f:
        return list(csv.DictReader(f))


def host_timestamps(folder):
    """host_timestamps.csv as (index, host_timestamp_ns) pairs."""
    with open(os.path.join(folder, "host_timestamps.csv"), newline="") as f:
        return [(int(row["index"]), int(row["host_timestamp_ns"])) for row in csv.DictReader(f)]


def read_bytes(path):
    with open(path, "rb") as f:
        return f.read()


class Simulate(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.dir = cls.tmp.name
        cls.rig = quarter_rig(cls.dir)
        cls.folder = os.path.join(cls.dir, "seed5")
        cls.start_ns = time.time_ns()
        cls.result = tilth("simulate", cls.folder, "--preset", "case_b", "--frames", 3, "--seed", 5,
                           "--calibration", cls.rig)
        cls.end_ns = time.time_ns()

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def path(self, name):
        return os.path.join(self.dir, name)

    def test_folder_holds_the_frames_the_options_ask_for(self):
        self.assertEqual(self.result.returncode, 0, self.result.stderr)
        self.assertEqual(self.result.stdout, self.folder + ": 3 frames (folder)\n")
        rows = frames_csv(self.folder)
        self.assertEqual([int(row["index"]) for row in rows], [0, 1, 2])
        for i, row in enumerate(rows):
            depth_ns = 1_000_000_000 + i * 1_000_000_000 // 30  # 30 frames/s, from 1 s
            self.assertEqual(int(row["depth_timestamp_ns"]), depth_ns)
            self.assertEqual(int(row["color_timestamp_ns"]), depth_ns + 400_000)
            self.assertEqual(row["ground_truth_mm"], "518.00")
            bits, kind, depth = read_png(os.path.join(self.folder, row["depth"]))
            self.assertEqual((bits, kind, depth.shape), (16, PNG_GRAY, (120, 160)))
            bits, kind, color = read_png(os.path.join(self.folder, row["color"]))
            self.assertEqual((bits, kind, color.shape), (8, PNG_RGB, (256, 320, 3)))
            bits, kind, mask = read_png(os.path.join(self.folder, row["mask"]))
            self.assertEqual((bits, kind, mask.shape), (8, PNG_GRAY, (120, 160)))
            self.assertTrue(set(np.unique(mask)) <= {0, 128, 255})
            self.assertIn(255, mask)  # case_b has straw
        # Host capture times: when each frame was rendered.
        host = host_timestamps(self.folder)
        self.assertEqual([index for index, _ in host], [0, 1, 2])
        host_ns = [ns for _, ns in host]
        self.assertEqual(host_ns, sorted(set(host_ns)))
        self.assertGreaterEqual(host_ns[0], self.start_ns)
        self.assertLessEqual(host_ns[-1], self.end_ns)
        with open(os.path.join(self.folder, "recording.json")) as f:
            recording = json.load(f)
        self.assertEqual(recording["color_format"], "bgr8")
        self.assertIn("--seed 5", recording["description"])
        self.assertEqual(read_bytes(os.path.join(self.folder, recording["calibration"])),
                         read_bytes(self.rig))

    def test_the_seed_decides_the_frames(self):
        same = self.path("seed5-again")
        other = self.path("seed6")
        self.assertEqual(tilth("simulate", same, "--preset", "case_b", "--frames", 1, "--seed", 5,
                               "--calibration", self.rig).returncode, 0)
        self.assertEqual(tilth("simulate", other, "--preset", "case_b", "--frames", 1, "--seed", 6,
                               "--calibration", self.rig).returncode, 0)
        for name in ("depth/000000.png", "color/000000.png", "mask/000000.png"):
            self.assertEqual(read_bytes(os.path.join(same, name)),
                             read_bytes(os.path.join(self.folder, name)), name)
        _, _, depth5 = read_png(os.path.join(self.folder, "depth/000000.png"))
        _, _, depth6 = read_png(os.path.join(other, "depth/000000.png"))
        self.assertGreater(np.count_nonzero(depth5 != depth6), depth5.size // 2)

    def test_sensor_noise_scales_with_its_options(self):
        # The same seed with and without noise: the difference is the noise alone. Its sd
        # at --tof-noise 3 is three times that at 1, at --color-noise 8 four times that at 2
        # (within 5 %: 8-bit rounding adds 0.29 DN, and the flat preset's thousands of
        # pixels give each sd a few tenths of a per cent).
        renders = {}
        for name, options in (("quiet", ["--tof-noise", 0, "--color-noise", 0]),
                              ("low", ["--tof-noise", 1, "--color-noise", 2]),
                              ("high", ["--tof-noise", 3, "--color-noise", 8])):
            folder = self.path("noise-" + name)
            result = tilth("simulate", folder, "--preset", "flat", "--frames", 1,
                           "--calibration", self.rig, *options)
            self.assertEqual(result.returncode, 0, result.stderr)
            renders[name] = {kind: read_png(os.path.join(folder, kind, "000000.png"))[2]
                             .astype(np.float64) for kind in ("depth", "color")}
        for kind, ratio in (("depth", 3.0), ("color", 4.0)):
            low = np.std(renders["low"][kind] - renders["quiet"][kind])
            high = np.std(renders["high"][kind] - renders["quiet"][kind])
            self.assertGreater(low, 0.0, kind)
            self.assertAlmostEqual(high / low, ratio, delta=0.05 * ratio, msg=kind)

    def test_output_format_by_extension_or_flag(self):
        cases = [("b.rec", ["--format", "mcap"], "mcap"),
                 ("c.mcap", ["--format", "folder"], "folder"),
                 ("d.mcap", ["--color-format", "bayer_rggb8", "--compression", "lz4"], "mcap")]
        for name, options, kind in cases:
            with self.subTest(name=name):
                result = tilth("simulate", self.path(name), "--preset", "flat", "--frames", 1,
                               "--calibration", self.rig, *options)
                self.assertEqual(result.returncode, 0, result.stderr)
                self.assertIn("1 frames (%s)" % kind, result.stdout)
                if kind == "mcap":
                    self.assertEqual(read_bytes(self.path(name))[:8], MCAP_MAGIC)
                else:
                    self.assertTrue(os.path.isfile(self.path(name + "/recording.json")))
        info = tilth("recording", "info", self.path("d.mcap")).stdout
        self.assertIn("compression: lz4", info)

    def test_fps_paces_like_a_live_camera_and_counts_drops(self):
        start = time.monotonic()
        result = tilth("simulate", self.path("paced.mcap"), "--preset", "flat", "--frames", 4,
                       "--fps", 10, "--calibration", self.rig)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertGreaterEqual(time.monotonic() - start, 0.3)  # 4 frames 0.1 s apart
        self.assertIn("4 frames (mcap), 0 dropped", result.stdout)

    def test_bad_input_names_the_option(self):
        existing = self.path("existing.mcap")
        with open(existing, "w") as f:
            f.write("not a recording")
        cases = [
            (["--preset", "case_z"], 2,
             r"tilth simulate:--preset: parameter 'preset': expected one of 'flat', 'case_a', .*"
             r"got \"case_z\""),
            (["--frames", "-1"], 2,
             r"tilth simulate:--frames: parameter 'frames': expected an integer >= 0, got -1"),
            (["--fps", "fast"], 2, r"tilth simulate:--fps: parameter 'fps': expected a number"),
            (["--format", "avi"], 2, r"--format: expected mcap or folder, got 'avi'"),
            (["--compression", "lz4"], 2, r"--compression is for MCAP output"),
            (["--calibration", self.path("none.json")], 1, r"none\.json: cannot read"),
            (["--frobnicate"], 2, r"unknown option --frobnicate"),
        ]
        for options, code, message in cases:
            with self.subTest(options=options):
                result = tilth("simulate", self.path("bad"), "--calibration", self.rig, *options)
                self.assertEqual(result.returncode, code, result.stderr)
                self.assertRegex(result.stderr, message)
        result = tilth("simulate", existing, "--calibration", self.rig)
        self.assertEqual(result.returncode, 1)
        self.assertIn(existing + ": exists; use --overwrite to replace it", result.stderr)
        # --overwrite replaces a recording, not any file.
        result = tilth("simulate", existing, "--calibration", self.rig, "--overwrite")
        self.assertEqual(result.returncode, 1)
        self.assertIn(existing + ": exists and is not an MCAP file", result.stderr)
        self.assertEqual(read_bytes(existing), b"not a recording")
        open(existing, "w").close()
        self.assertEqual(tilth("simulate", existing, "--calibration", self.rig, "--preset", "flat",
                               "--frames", 1, "--overwrite").returncode, 0)
        self.assertEqual(read_bytes(existing)[:8], MCAP_MAGIC)


class Recording(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.dir = self.tmp.name

    def tearDown(self):
        self.tmp.cleanup()

    def path(self, name):
        return os.path.join(self.dir, name)

    def test_a_folder_from_elsewhere_survives_import_and_export(self):
        # Written by check_folder.py's own code, with the calibration inline and truth
        # and masks on every second frame only.
        calibration = small_calibration()
        frames = make_frames(5, 1, calibration)
        source = self.path("in")
        write_input_recording(source, frames, "bayer_gbrg8", calibration)
        with open(os.path.join(source, "recording.json")) as f:
            recording = json.load(f)
        recording["calibration"] = calibration
        with open(os.path.join(source, "recording.json"), "w") as f:
            json.dump(recording, f)

        imported = tilth("recording", "import", source, self.path("in.mcap"),
                         "--compression", "lz4")
        self.assertEqual(imported.returncode, 0, imported.stderr)
        self.assertEqual(imported.stdout, self.path("in.mcap") + ": 5 frames from " + source + "\n")
        info = tilth("recording", "info", self.path("in.mcap")).stdout
        for line in ("compression: lz4", "/tof/raw  5 messages", "/color/image  5 messages",
                     "/truth  2 messages", "/truth/mask  2 messages", "attachments: rig.calib.json"):
            self.assertIn(line, info)

        exported = tilth("recording", "export", self.path("in.mcap"), self.path("out"))
        self.assertEqual(exported.returncode, 0, exported.stderr)
        rows = frames_csv(self.path("out"))
        self.assertEqual(len(rows), len(frames))
        for frame, row in zip(frames, rows):
            with self.subTest(index=frame["index"]):
                self.assertEqual(int(row["index"]), frame["index"])
                self.assertEqual(int(row["depth_timestamp_ns"]), frame["depth_ns"])
                self.assertEqual(int(row["color_timestamp_ns"]), frame["color_ns"])
                _, _, depth = read_png(self.path("out/" + row["depth"]))
                np.testing.assert_array_equal(depth.astype(np.uint16), frame["depth"])
                _, _, color = read_png(self.path("out/" + row["color"]))
                np.testing.assert_array_equal(color, frame["color"])
                if frame["mask"] is None:
                    self.assertEqual((row["mask"], row["ground_truth_mm"]), ("", ""))
                else:
                    _, _, mask = read_png(self.path("out/" + row["mask"]))
                    np.testing.assert_array_equal(mask, frame["mask"])
                    self.assertEqual(float(row["ground_truth_mm"]), frame["truth"])
        with open(self.path("out/recording.json")) as f:
            self.assertEqual(json.load(f)["color_format"], "bayer_gbrg8")
        with open(self.path("out/rig.calib.json")) as f:
            self.assertEqual(json.load(f), calibration)
        # Without host times the MCAP file's log times are the device times, and so are the
        # host times exported from it.
        self.assertEqual(host_timestamps(self.path("out")),
                         [(frame["index"], frame["depth_ns"]) for frame in frames])

    def test_host_timestamps_survive_import_and_export(self):
        calibration = small_calibration()
        frames = make_frames(4, 3, calibration)
        frames[2]["host_ns"] = frames[0]["host_ns"] - 2_000_000_000  # the clock set back
        source = self.path("in")
        write_input_recording(source, frames, "bgr8", calibration, host_timestamps=True)
        for command, args in (("import", (source, self.path("in.mcap"))),
                              ("export", (self.path("in.mcap"), self.path("out")))):
            result = tilth("recording", command, *args)
            self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(host_timestamps(self.path("out")),
                         [(frame["index"], frame["host_ns"]) for frame in frames])
        self.assertEqual(read_bytes(self.path("out/host_timestamps.csv")),
                         read_bytes(os.path.join(source, "host_timestamps.csv")))
        # The log times are printed in UTC with milliseconds; the latest is frame 3's host
        # time (1_763_800_000.10045 s).
        info = tilth("recording", "info", self.path("in.mcap")).stdout
        self.assertRegex(info, r"\nduration:    \d+\.\d{3} s \(log time "
                               r"2025-11-22T08:26:\d\d\.\d{3}Z to 2025-11-22T08:26:40\.100Z\)\n")

    def test_no_output_is_written_over_its_input_or_anything_but_a_recording(self):
        calibration = small_calibration()
        source = self.path("in")
        write_input_recording(source, make_frames(2, 3, calibration), "bgr8", calibration)
        mcap = self.path("in.mcap")
        self.assertEqual(tilth("recording", "import", source, mcap).returncode, 0)
        folder_files = {name: read_bytes(os.path.join(source, name))
                        for name in ("recording.json", "frames.csv")}
        mcap_bytes = read_bytes(mcap)
        notes = self.path("notes")
        os.makedirs(notes)
        with open(os.path.join(notes, "todo.txt"), "w") as f:
            f.write("not a recording\n")
        cases = [
            (["import", source, os.path.join(source, "recording.json"), "--overwrite"],
             re.escape(os.path.join(source, "recording.json")) + r": lies inside the input "),
            (["import", source, source, "--overwrite"], re.escape(source) + r": is the input "),
            (["import", os.path.join(self.dir, "in"), self.dir + "/", "--overwrite"],
             r": holds the input "),
            (["export", mcap, self.dir, "--overwrite"], re.escape(self.dir) + r": holds the input "),
            (["import", source, os.path.join(notes, "todo.txt"), "--overwrite"],
             r"todo.txt: exists and is not an MCAP file \(it does not start with the MCAP magic "
             r"bytes\); --overwrite replaces only a recording"),
            (["export", mcap, notes, "--overwrite"],
             re.escape(notes) + r": exists and is not an image-folder recording \(no "
                                r"recording.json\); --overwrite replaces only a recording"),
            (["repair", mcap, mcap, "--overwrite"], re.escape(mcap) + r": is the input "),
        ]
        for args, message in cases:
            with self.subTest(args=args):
                result = tilth("recording", *args)
                self.assertEqual(result.returncode, 1, result.stderr)
                self.assertRegex(result.stderr, message)
        for name, data in folder_files.items():
            self.assertEqual(read_bytes(os.path.join(source, name)), data, name)
        self.assertEqual(read_bytes(mcap), mcap_bytes)
        self.assertEqual(read_bytes(os.path.join(notes, "todo.txt")), b"not a recording\n")
        # What is a recording is replaced.
        self.assertEqual(tilth("recording", "import", source, mcap, "--overwrite").returncode, 0)
        self.assertEqual(tilth("recording", "export", mcap, self.path("out")).returncode, 0)
        result = tilth("recording", "export", mcap, self.path("out"), "--overwrite")
        self.assertEqual(result.returncode, 0, result.stderr)

    def test_bad_input_says_what_and_where(self):
        folder = self.path("folder")
        os.makedirs(folder)
        with open(os.path.join(folder, "frames.csv"), "w") as f:
            f.write("index\n")
        not_mcap = os.path.join(folder, "frames.csv")
        taken = self.path("taken.mcap")
        with open(taken, "w") as f:
            f.write("taken")
        cases = [
            ([], 2, r"expected a command"),
            (["frobnicate"], 2, r"unknown command 'frobnicate'"),
            (["info"], 2, r"info takes FILE"),
            (["export", not_mcap], 2, r"export takes FILE DIR"),
            (["info", folder], 1, re.escape(folder) + r": is a folder; info reads MCAP files"),
            (["info", not_mcap], 1,
             re.escape(not_mcap) + r": not an MCAP file \(expected the magic bytes"),
            (["export", not_mcap, self.path("out")], 1, re.escape(not_mcap) + r": not an MCAP file"),
            (["export", not_mcap, folder], 1,
             re.escape(folder) + r": holds the input " + re.escape(not_mcap) +
             r"; expected an output apart from it"),
            (["import", folder, self.path("x.mcap")], 1,
             re.escape(folder) + r"/recording.json: cannot read \(is this an image-folder "
                                 r"recording\?\)"),
            (["import", folder, not_mcap], 1,
             re.escape(not_mcap) + r": lies inside the input " + re.escape(folder)),
            (["import", folder, taken], 1, re.escape(taken) + r": exists; use --overwrite to "
                                                              r"replace it"),
        ]
        for args, code, message in cases:
            with self.subTest(args=args):
                result = tilth("recording", *args)
                self.assertEqual(result.returncode, code, result.stderr)
                self.assertRegex(result.stderr, message)
        with open(os.path.join(folder, "recording.json"), "w") as f:
            json.dump({"format": "tilth-image-folder/1", "color_format": "bgr8"}, f)
        result = tilth("recording", "import", folder, self.path("x.mcap"))
        self.assertIn(folder + "/recording.json:/calibration: missing required field", result.stderr)
        with open(os.path.join(folder, "recording.json"), "w") as f:
            json.dump({"format": "tilth-image-folder/1", "color_format": "bgr8",
                       "calibration": paper_rig_path()}, f)
        result = tilth("recording", "import", folder, self.path("x.mcap"), "--compression", "zip")
        self.assertEqual(result.returncode, 2)
        self.assertIn("tilth recording import:--compression: parameter 'compression': expected one "
                      "of 'zstd', 'lz4', 'none', got \"zip\"", result.stderr)
        result = tilth("recording", "import", folder, self.path("x.mcap"))
        self.assertEqual(result.returncode, 1)
        # The rest is the source stage's to check, with its own message.
        self.assertIn("frames.csv:1: missing required column 'depth_timestamp_ns'", result.stderr)


if __name__ == "__main__":
    unittest.main()

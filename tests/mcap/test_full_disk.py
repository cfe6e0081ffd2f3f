"""mcap.writer on a full disk (a file size limit, RLIMIT_FSIZE, with SIGXFSZ ignored: writes
fail with EFBIG as they do with ENOSPC): the process does not abort, the recording stops
with the frames before the failure readable (`tilth recording info`, `repair`), the frames
not stored are reported, `tilth run` exits with the data-lost code 3, and the rest of the
graph (a CSV of every frame) runs on."""
import json
import os
import re
import resource
import signal
import subprocess
import sys
import tempfile
import unittest

SUPPORT = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "support")
sys.path.insert(0, SUPPORT)
from rigs import quarter_rig  # noqa: E402

TILTH = os.environ["TILTH_BIN"]
SOURCE = os.environ["TILTH_SOURCE_DIR"]
PLUGIN_DIR = os.environ["TILTH_TEST_PLUGIN_DIR"]

FRAMES = 40
LIMIT = 3_000_000  # bytes: about ten frames of the quarter rig, uncompressed


def limit_file_size():
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    resource.setrlimit(resource.RLIMIT_FSIZE, (LIMIT, LIMIT))


def tilth(*args):
    return subprocess.run([TILTH, *map(str, args)], capture_output=True, text=True, timeout=120)


def info(path):
    """`tilth recording info`: (exit code, has a summary, messages, messages on /tof/raw)."""
    result = tilth("recording", "info", path)
    total = re.search(r"^messages:\s+(\d+) in", result.stdout, re.M)
    raw = re.search(r"^  /tof/raw\s+(\d+) messages", result.stdout, re.M)
    return (result.returncode, "summary:     yes" in result.stdout,
            int(total.group(1)) if total else None, int(raw.group(1)) if raw else None)


class FullDisk(unittest.TestCase):
    def test_the_recording_stops_and_the_graph_runs_on(self):
        with tempfile.TemporaryDirectory() as tmp:
            rig = quarter_rig(tmp)
            recording = os.path.join(tmp, "run.mcap")
            csv_dir = os.path.join(tmp, "csv")
            graph = os.path.join(tmp, "graph.json")
            with open(graph, "w") as f:
                json.dump({
                    "nodes": {
                        "scene": {"type": "synthetic.scene",
                                  "params": {"calibration": rig, "preset": "flat",
                                             "frames": FRAMES}},
                        "writer": {"type": "mcap.writer",
                                   "params": {"path": recording, "calibration": rig,
                                              "compression": "none", "chunk_size": 250_000,
                                              "when_behind": "wait"}},
                        "distance": {"type": "testdistance.sequence",
                                     "params": {"frames": FRAMES, "fps": 0}},
                        "csv": {"type": "sinks.csv",
                                "params": {"path": os.path.join(csv_dir, "run.csv"),
                                           "rotate_bytes": 2000}}},
                    "edges": [["scene.raw", "writer.raw"], ["scene.color", "writer.color"],
                              ["scene.truth", "writer.truth"],
                              ["distance.distance", "csv.distance"]]}, f)
            result = subprocess.run(
                [TILTH, "run", graph, "--quiet"], capture_output=True, text=True, timeout=300,
                env=dict(os.environ, TILTH_PLUGIN_PATH=PLUGIN_DIR), preexec_fn=limit_file_size)

            self.assertEqual(result.returncode, 3, result.stderr)
            lost = re.search(r"^tilth run: data lost: node 'writer' \(mcap\.writer\): (\d+) "
                             r"frame\(s\) not stored; first report: (.*)$", result.stderr, re.M)
            self.assertIsNotNone(lost, result.stderr)
            first = lost.group(2)
            self.assertRegex(first, "^" + re.escape(recording) + r": cannot write (before|at) "
                             r"offset \d+: File too large; writing stopped, the file keeps its "
                             r"first (\d+) bytes \((\d+) messages\) without a summary; recording "
                             r"stopped: \d+ frame\(s\) not stored so far, the file keeps the "
                             r"(\d+) before")
            kept_bytes, kept_messages, kept_frames = map(int, re.search(
                r"first (\d+) bytes \((\d+) messages\).* keeps the (\d+) before", first).groups())
            self.assertEqual(int(lost.group(1)), FRAMES - kept_frames)
            self.assertGreater(kept_frames, 3)
            self.assertLess(kept_frames, FRAMES)
            self.assertEqual(os.path.getsize(recording), kept_bytes)  # cut back to whole records

            # The CSV got every frame, during the full disk and after it.
            rows = []
            for name in sorted(os.listdir(csv_dir), key=lambda n: (len(n), n)):
                with open(os.path.join(csv_dir, name)) as f:
                    rows += [line.split(",")[0] for line in f.read().splitlines()[1:]]
            self.assertEqual(rows, [str(i) for i in range(FRAMES)])

            # The frames before the failure are readable (info says the summary is missing,
            # exit code 3), and repair gives them a summary.
            self.assertEqual(info(recording), (3, False, kept_messages, kept_frames))
            repaired = os.path.join(tmp, "repaired.mcap")
            repair = tilth("recording", "repair", recording, repaired)
            self.assertEqual(repair.returncode, 0, repair.stderr)
            self.assertEqual(info(repaired), (0, True, kept_messages, kept_frames))


if __name__ == "__main__":
    unittest.main()

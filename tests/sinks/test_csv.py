"""sinks.csv in `tilth run`s of a known distance sequence (testdistance.sequence): the
header and one exact row per frame, rotation into numbered files by size and by age,
nothing but the last line damaged by a SIGKILL, the error for an unwritable path, and a
full disk (a file size limit, RLIMIT_FSIZE): whole rows only, the rows lost counted and
reported, exit code 3, and the rest of the graph running on."""
import json
import os
import re
import resource
import signal
import subprocess
import tempfile
import time
import unittest

TILTH = os.environ["TILTH_BIN"]
PLUGIN_DIR = os.environ["TILTH_TEST_PLUGIN_DIR"]
with open(os.path.join(os.environ["TILTH_SOURCE_DIR"], "CMakeLists.txt")) as cmake_lists:
    RELEASE = re.search(r"project\(Tilth VERSION ([0-9.]+)", cmake_lists.read()).group(1)

HEADER = ("index,device_timestamp_ns,host_timestamp_ns,distance_mm,valid,cause,soil_fraction,"
          "soil_pixels,spread_mm,confidence,held_ms,latency_ms,truth_mm,tilth_version")
FIELDS = HEADER.split(",")


def write_graph(directory, csv_params, source_params):
    path = os.path.join(directory, "graph.json")
    with open(path, "w") as f:
        json.dump({"nodes": {"source": {"type": "testdistance.sequence", "params": source_params},
                             "csv": {"type": "sinks.csv", "params": csv_params}},
                   "edges": [["source.distance", "csv.distance"]]}, f)
    return path


def tilth_command(graph):
    return [TILTH, "run", graph, "--quiet"]


def tilth_env():
    return dict(os.environ, TILTH_PLUGIN_PATH=PLUGIN_DIR)


def run(directory, csv_params, source_params):
    graph = write_graph(directory, csv_params, source_params)
    return subprocess.run(tilth_command(graph), capture_output=True, text=True, timeout=30,
                          env=tilth_env())


def read_lines(path):
    with open(path) as f:
        return f.read().split("\n")


def rows_of(path):
    """A whole file's rows as dicts; checks the header and that the file ends a line."""
    lines = read_lines(path)
    assert lines[0] == HEADER, lines[0]
    assert lines[-1] == "", "last line of %s not ended" % path
    return [dict(zip(FIELDS, line.split(","))) for line in lines[1:-1]]


def rotated_files(directory):
    """run.csv, run.1.csv, run.2.csv, ... in order; fails on any other file name."""
    names = sorted(name for name in os.listdir(directory) if name != "graph.json")
    numbers = []
    for name in names:
        match = re.fullmatch(r"run(?:\.(\d+))?\.csv", name)
        assert match, "unexpected file " + name
        numbers.append(int(match.group(1) or 0))
    numbers.sort()
    assert numbers == list(range(len(numbers))), names
    return [os.path.join(directory, "run.csv" if n == 0 else "run.%d.csv" % n) for n in numbers]


class Rows(unittest.TestCase):
    def test_header_and_one_exact_row_per_frame(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "out", "run.csv")  # the directory is made
            result = run(tmp, {"path": path}, {"frames": 20, "fps": 0, "first_frame_id": 100,
                                               "invalid_every": 5})
            self.assertEqual(result.returncode, 0, result.stderr)
            rows = rows_of(path)
        self.assertEqual(len(rows), 20)
        for i, row in enumerate(rows):
            valid = (i + 1) % 5 != 0
            self.assertEqual(row["index"], str(100 + i))
            self.assertEqual(row["device_timestamp_ns"], row["host_timestamp_ns"])
            self.assertGreater(int(row["host_timestamp_ns"]), 0)
            self.assertEqual(row["distance_mm"], "%.3f" % round(518.23 + 0.37 * i, 2)
                             if valid else "nan")
            self.assertEqual(row["valid"], "1" if valid else "0")
            self.assertEqual(row["cause"], "" if valid else "too_little_soil")
            self.assertEqual(row["soil_fraction"], "%.4f" % (i / 100 + 0.0012))
            self.assertEqual(row["soil_pixels"], str(1000 + i))
            self.assertEqual(row["spread_mm"], "1.500")
            self.assertEqual(row["confidence"], "%.3f" % (i / 100 + 0.005))
            self.assertEqual(row["held_ms"], "")  # no estimation.temporal before the sink
            self.assertGreaterEqual(float(row["latency_ms"]), 0.0)
            self.assertEqual(row["truth_mm"], "")  # no truth input connected
            self.assertEqual(row["tilth_version"], RELEASE)

    def test_a_held_distance_is_valid_with_its_age(self):
        """estimation.temporal between the source and the sink holds the distance over each
        invalid frame: that row shows the frame before's distance, with held_ms its age."""
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "run.csv")
            graph = os.path.join(tmp, "graph.json")
            with open(graph, "w") as f:
                json.dump({"nodes": {
                    "source": {"type": "testdistance.sequence",
                               "params": {"frames": 20, "fps": 50, "invalid_every": 5}},
                    "hold": {"type": "estimation.temporal", "params": {"max_hold_ms": 500}},
                    "csv": {"type": "sinks.csv", "params": {"path": path}}},
                    "edges": [["source.distance", "hold.distance"],
                              ["hold.distance", "csv.distance"]]}, f)
            result = subprocess.run(tilth_command(graph), capture_output=True, text=True,
                                    timeout=30, env=tilth_env())
            self.assertEqual(result.returncode, 0, result.stderr)
            rows = rows_of(path)
        self.assertEqual(len(rows), 20)
        for i, row in enumerate(rows):
            self.assertEqual(row["valid"], "1")
            if (i + 1) % 5 != 0:
                self.assertEqual(row["held_ms"], "")
                self.assertEqual(row["distance_mm"], "%.3f" % round(518.23 + 0.37 * i, 2))
                continue
            self.assertEqual(row["distance_mm"], rows[i - 1]["distance_mm"])
            # Capture times of frames 20 ms apart, each taken when the frame is produced.
            since_ms = (int(row["host_timestamp_ns"]) - int(rows[i - 1]["host_timestamp_ns"])) / 1e6
            self.assertAlmostEqual(float(row["held_ms"]), since_ms, delta=0.05)  # 1 decimal
            self.assertGreater(float(row["held_ms"]), 10.0)


class Rotation(unittest.TestCase):
    def test_by_size_no_file_grows_past_the_limit(self):
        limit = 400
        with tempfile.TemporaryDirectory() as tmp:
            result = run(tmp, {"path": os.path.join(tmp, "run.csv"), "rotate_bytes": limit},
                         {"frames": 30, "fps": 0})
            self.assertEqual(result.returncode, 0, result.stderr)
            files = rotated_files(tmp)
            rows = [rows_of(path) for path in files]
            sizes = [os.path.getsize(path) for path in files]
        self.assertGreater(len(files), 3)
        self.assertEqual([row["index"] for part in rows for row in part],
                         [str(i) for i in range(30)])
        for i, size in enumerate(sizes):
            self.assertLessEqual(size, limit, files[i])
            self.assertGreater(len(rows[i]), 0)
            if i + 1 < len(files):  # full: the next file's first row did not fit
                next_row = ",".join(rows[i + 1][0][field] for field in FIELDS) + "\n"
                self.assertGreater(size + len(next_row), limit, files[i])

    def test_by_age_a_new_file_each_second(self):
        with tempfile.TemporaryDirectory() as tmp:
            result = run(tmp, {"path": os.path.join(tmp, "run.csv"), "rotate_seconds": 1},
                         {"frames": 125, "fps": 50})
            self.assertEqual(result.returncode, 0, result.stderr)
            files = rotated_files(tmp)
            rows = [rows_of(path) for path in files]
        self.assertEqual(len(files), 3, [len(part) for part in rows])  # 2.5 s of frames
        self.assertEqual([row["index"] for part in rows for row in part],
                         [str(i) for i in range(125)])
        # Files are timed by when rows are written, a few ms after capture.
        for part in rows[:-1]:
            span_s = (int(part[-1]["host_timestamp_ns"]) - int(part[0]["host_timestamp_ns"])) / 1e9
            self.assertGreater(span_s, 0.8)
            self.assertLess(span_s, 1.05)


class KillSafety(unittest.TestCase):
    def test_sigkill_mid_run_damages_at_most_the_last_line(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "run.csv")
            graph = write_graph(tmp, {"path": path}, {"frames": 0, "fps": 2000})
            process = subprocess.Popen(tilth_command(graph), stdout=subprocess.DEVNULL,
                                       stderr=subprocess.DEVNULL, env=tilth_env())
            deadline = time.monotonic() + 10
            while time.monotonic() < deadline and (
                    not os.path.exists(path) or os.path.getsize(path) < 50_000):
                time.sleep(0.05)
            process.send_signal(signal.SIGKILL)
            process.wait(timeout=10)
            lines = read_lines(path)
        self.assertEqual(process.returncode, -signal.SIGKILL)
        self.assertEqual(lines[0], HEADER)
        complete, last = lines[1:-1], lines[-1]  # `last` is "" unless cut mid-row
        self.assertGreater(len(complete), 400)
        for i, line in enumerate(complete):
            fields = line.split(",")
            self.assertEqual(len(fields), len(FIELDS), line)
            self.assertEqual(int(fields[0]), i)
            float(fields[3]), float(fields[9])  # noqa: B018 (parses)
        if last:  # cut mid-row: the start of the next frame's row
            self.assertLessEqual(len(last.split(",")), len(FIELDS))
            self.assertTrue(str(len(complete)).startswith(last.split(",")[0]), last)


def limit_file_size(limit):
    """In the child: files stop growing at `limit` bytes, with EFBIG as on a full disk."""
    def apply():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
    return apply


def run_limited(directory, nodes, edges, limit, *options):
    graph = os.path.join(directory, "graph.json")
    with open(graph, "w") as f:
        json.dump({"nodes": nodes, "edges": edges}, f)
    return subprocess.run(tilth_command(graph) + list(options), capture_output=True, text=True,
                          timeout=60, env=tilth_env(), preexec_fn=limit_file_size(limit))


def whole_rows(test, path):
    """A file's rows, after checking every line has every column."""
    rows = rows_of(path)
    for row in rows:
        test.assertEqual(len(row), len(FIELDS), row)
        test.assertNotIn(None, row.values(), row)
        float(row["distance_mm"]), float(row["latency_ms"])  # noqa: B018 (parses)
    with open(path) as f:
        test.assertTrue(all(len(line.split(",")) == len(FIELDS) for line in f), path)
    return rows


def lost_frames(test, stderr, node):
    match = re.search(r"^tilth run: data lost: node '%s' \(sinks\.csv\): (\d+) frame\(s\) not "
                      r"stored; first report: (.*)$" % node, stderr, re.M)
    test.assertIsNotNone(match, stderr)
    return int(match.group(1)), match.group(2)


class FullDisk(unittest.TestCase):
    LIMIT = 8000

    def test_rows_that_do_not_fit_are_lost_whole_and_the_graph_runs_on(self):
        with tempfile.TemporaryDirectory() as tmp:
            full = os.path.join(tmp, "full.csv")
            other_dir = os.path.join(tmp, "other")
            nodes = {"source": {"type": "testdistance.sequence",
                                "params": {"frames": 400, "fps": 0}},
                     "full": {"type": "sinks.csv", "params": {"path": full}},
                     "other": {"type": "sinks.csv",
                               "params": {"path": os.path.join(other_dir, "run.csv"),
                                          "rotate_bytes": 2000}}}
            edges = [["source.distance", "full.distance"], ["source.distance", "other.distance"]]
            result = run_limited(tmp, nodes, edges, self.LIMIT)
            self.assertEqual(result.returncode, 3, result.stderr)
            rows = whole_rows(self, full)
            self.assertLessEqual(os.path.getsize(full), self.LIMIT)
            self.assertGreater(len(rows), 40)
            self.assertEqual([row["index"] for row in rows], [str(i) for i in range(len(rows))])
            lost, first = lost_frames(self, result.stderr, "full")
            self.assertEqual(lost, 400 - len(rows))
            self.assertEqual(first, "%s: File too large; the row of frame %d was not written "
                             "(1 row(s) lost so far); rows are written again when the disk "
                             "takes them" % (full, len(rows)))
            self.assertIn("error: runtime: node 'full' (sinks.csv) lost data: " + first +
                          "; the graph runs on", result.stderr)
            # The other sink got every frame, before the full disk and after it.
            other = [row for path in rotated_files(other_dir) for row in whole_rows(self, path)]
            self.assertEqual([row["index"] for row in other], [str(i) for i in range(400)])

    def test_rows_are_written_again_when_the_disk_takes_them(self):
        """A new file each second: each fills up, then loses rows until the next."""
        with tempfile.TemporaryDirectory() as tmp:
            nodes = {"source": {"type": "testdistance.sequence",
                                "params": {"frames": 750, "fps": 300}},
                     "csv": {"type": "sinks.csv",
                             "params": {"path": os.path.join(tmp, "run.csv"),
                                        "rotate_seconds": 1}}}
            result = run_limited(tmp, nodes, [["source.distance", "csv.distance"]], 3000)
            self.assertEqual(result.returncode, 3, result.stderr)
            files = rotated_files(tmp)
            rows = [whole_rows(self, path) for path in files]
        self.assertGreaterEqual(len(files), 2)
        for part in rows:
            self.assertGreater(len(part), 20)
            indices = [int(row["index"]) for row in part]
            self.assertEqual(indices, list(range(indices[0], indices[0] + len(part))))
        written = sum(len(part) for part in rows)
        lost, _ = lost_frames(self, result.stderr, "csv")
        self.assertEqual(lost + written, 750)
        resumed = re.findall(r"warning: csv: (\S+): writing rows again; (\d+) row\(s\) lost "
                             r"\(frames (\d+) to (\d+)\)", result.stderr)
        self.assertEqual(len(resumed), len(files) - 1, result.stderr)
        for (path, count, first, last), part in zip(resumed, rows[1:]):
            self.assertEqual(int(last) + 1, int(part[0]["index"]))
            self.assertEqual(int(count), int(last) - int(first) + 1)


class Errors(unittest.TestCase):
    def test_a_path_that_cannot_be_written_stops_the_run_naming_it(self):
        with tempfile.TemporaryDirectory() as tmp:
            not_a_directory = os.path.join(tmp, "plain-file")
            open(not_a_directory, "w").close()
            for path, error in [
                    (tmp, tmp + ": cannot open for writing: Is a directory (parameter 'path' "
                          "must name a file in a writable directory)"),
                    (os.path.join(not_a_directory, "run.csv"),
                     os.path.join(not_a_directory, "run.csv") + ": cannot create its directory "
                     + not_a_directory + ": Not a directory")]:
                result = run(tmp, {"path": path}, {"frames": 1})
                self.assertEqual(result.returncode, 1, result.stderr)
                self.assertIn("node 'csv' (sinks.csv) failed to start: " + error, result.stderr)


if __name__ == "__main__":
    unittest.main()

"""The `tilth` command line, run as a user runs it: exit codes, messages, and clean
shutdown on SIGINT / SIGTERM with nothing lost."""
import json
import os
import re
import signal
import subprocess
import tempfile
import threading
import unittest

TILTH = os.environ["TILTH_BIN"]
SOURCE = os.environ["TILTH_SOURCE_DIR"]
PLANE = os.path.join(SOURCE, "tests", "cli", "plane.json")


def tilth(*args, timeout=60):
    return subprocess.run([TILTH, *args], capture_output=True, text=True, timeout=timeout)


class HelpAndInspection(unittest.TestCase):
    def test_every_command_has_help(self):
        for command in ["run", "validate", "plugins", "describe", "dot"]:
            result = tilth(command, "--help")
            self.assertEqual(result.returncode, 0, command)
            self.assertIn("usage: tilth " + command, result.stdout)
            self.assertEqual(tilth(command, "-h").stdout, result.stdout, command)
        for command in ["simulate", "recording", "ab", "train-segmenter", "calibrate", "doctor"]:
            result = tilth(command, "-h")
            self.assertEqual(result.returncode, 0, (command, result.stderr))
            self.assertIn("usage: tilth " + command, result.stdout)
        self.assertEqual(tilth("--help").returncode, 0)
        self.assertEqual(tilth("frobnicate").returncode, 2)

    def test_version_help_command_and_suggestions(self):
        with open(os.path.join(SOURCE, "CMakeLists.txt")) as f:
            release = re.search(r"project\(Tilth VERSION ([0-9.]+)", f.read()).group(1)
        result = tilth("--version")
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(result.stdout.splitlines()[0], "tilth " + release)
        self.assertRegex(result.stdout.splitlines()[1],
                         r"^built with (GCC|Clang) \d+, .*OpenCV \d+\.\d+, nlohmann-json "
                         r"\d+\.\d+\.\d+; plugin ABI \d+$")
        self.assertEqual(tilth("version").stdout, result.stdout)
        help_ = tilth("help", "validate")
        self.assertEqual(help_.returncode, 0, help_.stderr)
        self.assertEqual(help_.stdout, tilth("validate", "--help").stdout)
        # A command of a group: its own part of the group's usage, by either spelling.
        info = tilth("help", "recording", "info")
        self.assertEqual(info.returncode, 0, info.stderr)
        self.assertEqual(info.stdout, tilth("recording", "info", "-h").stdout)
        self.assertRegex(info.stdout, r"^usage: tilth recording\n\n  info FILE ")
        self.assertNotIn("repair", info.stdout)
        window = tilth("calibrate", "color-window", "--help").stdout
        self.assertIn("  color-window RIG.calib.json --distance-mm NEAR:FAR\n", window)
        self.assertNotIn("  solve ", window)
        self.assertEqual(tilth("help", "recording").stdout, tilth("recording", "--help").stdout)
        wrong = tilth("valdate", "g.json")
        self.assertEqual(wrong.returncode, 2)
        self.assertIn("tilth: unknown command 'valdate'; did you mean 'validate'?", wrong.stderr)

    def test_misspelt_subcommands_and_options_get_suggestions(self):
        for args, expected in (
                (("recording", "inf", "x.mcap"), "unknown command 'inf'; did you mean 'info'?"),
                (("calibrate", "slove"), "unknown command 'slove'; did you mean 'solve'?"),
                (("run", "g.json", "--frame", "3"),
                 "unknown option --frame; did you mean '--frames'? (see --help)"),
                (("doctor", "--jsn"), "unknown option --jsn; did you mean '--json'? (see --help)"),
                (("simulate", "out", "--preset", "case_c", "--frame", "2"),
                 "did you mean '--frames'?")):
            with self.subTest(args=args):
                result = tilth(*args)
                self.assertEqual(result.returncode, 2, result.stderr)
                self.assertIn(expected, result.stderr)

    def test_plugins_lists_types_with_ports(self):
        result = tilth("plugins")
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertIn("synthetic.tof_plane", result.stdout)
        self.assertIn("(in: -; out: raw:tilth.RawTofFrame)", result.stdout)
        self.assertIn("sinks.console", result.stdout)

    def test_describe_prints_the_schema(self):
        result = tilth("describe", "synthetic.tof_plane")
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertIn("distance_mm  number, default 518.0, allowed [50, 5000], unit mm",
                      result.stdout)
        markdown = tilth("describe", "synthetic.tof_plane", "--markdown").stdout
        self.assertIn("| `distance_mm` | number | `518.0` |", markdown)
        unknown = tilth("describe", "synthetic.tof_plan")
        self.assertEqual(unknown.returncode, 2)
        self.assertIn("unknown stage type 'synthetic.tof_plan'; did you mean 'synthetic.tof_plane'?",
                      unknown.stderr)

    def test_dot(self):
        result = tilth("dot", PLANE)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertIn('n0 -> n1 [label="raw → in\\ntilth.RawTofFrame"]', result.stdout)
        svg = subprocess.run(["dot", "-Tsvg"], input=result.stdout, capture_output=True, text=True)
        self.assertEqual(svg.returncode, 0, svg.stderr)
        self.assertIn("synthetic.tof_plane", svg.stdout)


class Validation(unittest.TestCase):
    def test_valid_graph(self):
        result = tilth("validate", PLANE)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertIn("valid, 2 nodes", result.stdout)

    def test_a_sub_graph_validates_as_a_fragment_and_does_not_run(self):
        chain = os.path.join(SOURCE, "graphs", "measurement-chain.json")
        result = tilth("validate", chain)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertIn("valid, 4 nodes; a fragment: a graph that includes it feeds its inputs "
                      "'raw (project.raw)', 'color (register.color)'; outputs "
                      "'distance (estimate.distance)'", result.stdout)
        result = tilth("run", chain)
        self.assertNotEqual(result.returncode, 0)
        self.assertIn("a fragment: nothing feeds its inputs 'raw (project.raw)', "
                      "'color (register.color)'", result.stderr)

    def test_invalid_graph_reports_every_problem(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "g.json")
            with open(path, "w") as f:
                f.write('{"nodes": {"camera": {"type": "synthetic.tof_plane",'
                        ' "params": {"distance_mm": 9000, "nosie_mm": 1}},'
                        ' "print": {"type": "sinks.consol"}},'
                        ' "edges": [["camera.raw", "print.in"]]}')
            result = tilth("validate", path)
        self.assertEqual(result.returncode, 2)
        self.assertIn(path + ":/nodes/camera/params/distance_mm: parameter 'distance_mm': expected "
                      "a number in [50, 5000], got 9000", result.stderr)
        self.assertIn(path + ":/nodes/camera/params/nosie_mm: unknown parameter 'nosie_mm' of "
                      "synthetic.tof_plane; did you mean 'noise_mm'?", result.stderr)
        self.assertIn(path + ":/nodes/print/type: unknown stage type 'sinks.consol'; did you mean "
                      "'sinks.console' or 'sinks.csv'?", result.stderr)
        self.assertIn("3 problem(s)", result.stderr)

    def test_bad_override_is_refused_before_running(self):
        result = tilth("run", PLANE, "--set", "camera.fps=fast")
        self.assertEqual(result.returncode, 2)
        self.assertIn("command line:--set camera.fps: parameter 'fps': expected a number in "
                      "[0, 1000], got \"fast\"", result.stderr)
        self.assertIn("nothing was run", result.stderr)


class UntrustedInput(unittest.TestCase):
    def test_numbers_are_read_whole(self):
        # "5abc" ran 5 frames and "-1" ran forever, both with exit code 0.
        for text in ["5abc", "-1", "0", " 5", "5.0", "1e3", ""]:
            result = tilth("run", PLANE, "--frames", text, "--set", "camera.fps=0", timeout=20)
            self.assertEqual(result.returncode, 2, text)
            self.assertIn("--frames: expected a whole number in [1, 1000000000000], got '%s'"
                          % text, result.stderr)
            self.assertEqual(result.stdout, "", text)

    def test_numbers_beyond_double_range_are_located(self):
        # These aborted with an uncaught exception (SIGABRT).
        result = tilth("validate", PLANE, "--set", "camera.distance_mm=1e999")
        self.assertEqual(result.returncode, 2, result.stderr)
        self.assertIn("command line:--set camera.distance_mm: expected a number within double "
                      "range (magnitude below 1.8e308), got 1e999", result.stderr)
        result = tilth("validate", PLANE, "--var", "x=1e999")
        self.assertEqual(result.returncode, 2, result.stderr)
        self.assertIn("command line:--var x: expected a number within double range", result.stderr)

    def test_include_of_a_device_or_fifo_is_refused(self):
        # "/dev/zero" was read until memory ran out; a FIFO waits for a writer forever.
        with tempfile.TemporaryDirectory() as tmp:
            fifo = os.path.join(tmp, "fifo.json")
            os.mkfifo(fifo)
            path = os.path.join(tmp, "g.json")
            with open(path, "w") as f:
                f.write('{"include": ["/dev/zero", "fifo.json"]}')
            result = tilth("validate", path, timeout=20)
        self.assertEqual(result.returncode, 2, result.stderr)
        self.assertIn(path + ":/include/0/file: is a character device; expected a regular file "
                      "(graph file '/dev/zero')", result.stderr)
        self.assertIn(path + ":/include/1/file: is a FIFO; expected a regular file (graph file '" +
                      fifo + "')", result.stderr)


class Simulate(unittest.TestCase):
    def test_scene_fields_change_the_preset(self):
        with tempfile.TemporaryDirectory() as work:
            out = os.path.join(work, "rec")
            result = tilth("simulate", out, "--preset", "case_a", "--frames", "1",
                           "--scene", '{"ground_distance_mm": 600, "straws": 0}')
            self.assertEqual(result.returncode, 0, result.stderr)
            with open(os.path.join(out, "frames.csv")) as f:
                self.assertTrue(f.read().splitlines()[1].endswith(",600.00"))
            with open(os.path.join(out, "recording.json")) as f:
                self.assertIn('--scene {"ground_distance_mm": 600, "straws": 0}',
                              json.load(f)["description"])

    def test_bad_scene_is_refused_by_name_and_writes_nothing(self):
        with tempfile.TemporaryDirectory() as work:
            out = os.path.join(work, "rec")
            for scene, expected in [
                    ('{"strawz": 1}', "no preset field 'strawz'; the fields are "
                                      "ground_distance_mm, stubble,"),
                    ('{"tilt_x_deg": 40}', "field 'tilt_x_deg': expected a number from -30 "
                                           "to 30, got 40"),
                    ('{"straws": 1', "expected a JSON object of preset fields such as "
                                     "{\"straws\": 600}, got the text '{\"straws\": 1'")]:
                result = tilth("simulate", out, "--scene", scene)
                self.assertEqual(result.returncode, 1, result.stderr)
                self.assertIn("parameter 'scene': " + expected, result.stderr)
                self.assertFalse(os.path.exists(out))


class Run(unittest.TestCase):
    def test_frame_limit_and_summary(self):
        result = tilth("run", PLANE, "--frames", "10", "--set", "camera.fps=0",
                       "--set", "print.every=1")
        self.assertEqual(result.returncode, 0, result.stderr)
        lines = result.stdout.splitlines()
        self.assertEqual(lines, ["frame %d: raw ToF 640x480" % i for i in range(10)])
        self.assertIn("10 frames completed, 0 dropped", result.stderr)
        self.assertRegex(result.stderr, r"camera\s+synthetic\.tof_plane\s+1[01]\s")

    def test_quiet_prints_no_info_lines(self):
        # Log lines are "LEVEL: WHERE: MESSAGE" (sdk/src/log.cpp). --quiet keeps warnings and
        # errors only, and drops the status line and the summary; what the graph prints stays.
        args = ["run", PLANE, "--frames", "3", "--set", "camera.fps=0", "--set", "print.every=1"]
        loud = tilth(*args)
        self.assertEqual(loud.returncode, 0, loud.stderr)
        self.assertRegex(loud.stderr, r"(?m)^info: run: running ")
        quiet = tilth(*args, "--quiet")
        self.assertEqual(quiet.returncode, 0, quiet.stderr)
        self.assertNotRegex(quiet.stderr, r"(?m)^info: ")
        self.assertNotIn("frames completed", quiet.stderr)
        self.assertEqual(quiet.stdout, loud.stdout)

    def stop_with(self, signum):
        process = subprocess.Popen(
            [TILTH, "run", PLANE, "--set", "camera.fps=100", "--set", "print.every=1",
             "--set", "runtime.when_full=block"],
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        # The signal comes once 21 frames are out, however long starting took (a sanitizer
        # build starts slowly); a run that prints nothing for a minute is killed.
        watchdog = threading.Timer(60, process.kill)
        watchdog.start()
        printed = []
        while len(printed) <= 20 and (line := process.stdout.readline()):
            printed.append(line)
        watchdog.cancel()
        process.send_signal(signum)
        # The rest through the same reader: its buffer may already hold the next frames'
        # lines, which communicate() (reading the pipe itself) would lose. stderr is a few
        # lines, far below a pipe's capacity, so reading stdout first cannot block tilth.
        watchdog = threading.Timer(30, process.kill)
        watchdog.start()
        out = "".join(printed) + process.stdout.read(1 << 20)
        err = process.stderr.read(1 << 20)
        process.wait()
        watchdog.cancel()
        self.assertEqual(process.returncode, 0, err)
        frames = [int(m.group(1)) for m in re.finditer(r"^frame (\d+):", out, re.M)]
        self.assertGreater(len(frames), 20)
        # Nothing lost: every admitted frame reached the sink, in order.
        self.assertEqual(frames, list(range(len(frames))))
        completed = int(re.search(r"(\d+) frames completed", err).group(1))
        self.assertEqual(completed, len(frames))
        self.assertIn("stopping; frames in flight finish", err)

    def test_sigterm_stops_cleanly(self):
        self.stop_with(signal.SIGTERM)

    def test_sigint_stops_cleanly(self):
        self.stop_with(signal.SIGINT)

    def test_a_closed_standard_output_ends_the_run(self):
        # `tilth run GRAPH | head -1`: the reader takes one line and goes.
        process = subprocess.Popen(
            [TILTH, "run", PLANE, "--set", "camera.fps=100", "--set", "print.every=1"],
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        try:
            first = process.stdout.readline()
            process.stdout.close()
            err = process.stderr.read(1 << 20)
            process.wait(timeout=30)
        finally:
            if process.poll() is None:
                process.kill()
                process.wait()
        self.assertEqual(first, "frame 0: raw ToF 640x480\n")
        self.assertEqual(process.returncode, 0, err)
        self.assertIn("print: ending the run: standard output is closed (Broken pipe): nothing "
                      "more can be printed", err)
        self.assertRegex(err, r"\d+ frames completed")


if __name__ == "__main__":
    unittest.main()

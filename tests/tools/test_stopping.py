"""Every tool that runs graphs or writes files, stopped as systemd stops a service
(SIGTERM) and as Ctrl-C does (SIGINT), with a thread started before main() by a
preloaded library (early_thread_preload.cpp), as OpenCV's, oneTBB's or GLib's static
constructors start them: the first signal stops the tool cleanly (exit code 0, the CSV
ends with a whole row, the MCAP file has its summary), a second exits at once with 130."""
import ctypes
import glob
import json
import os
import re
import signal
import subprocess
import sys
import tempfile
import time
import unittest

SUPPORT = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "support")
sys.path.insert(0, SUPPORT)
from rigs import quarter_rig  # noqa: E402

TILTH = os.environ["TILTH_BIN"]
SOURCE = os.environ["TILTH_SOURCE_DIR"]
PLUGIN_PATH = os.environ["TILTH_TEST_PLUGIN_PATH"]


def sanitizer_runtimes(program):
    """The sanitizer runtimes `program` links (libasan in an ASan build): they must come
    before any other library in LD_PRELOAD."""
    linked = subprocess.run(["ldd", program], stdout=subprocess.PIPE, text=True).stdout
    return [line.split("=>")[1].split()[0] for line in linked.splitlines()
            if re.match(r"\s*lib[alt]san\.so", line)]


PRELOAD = ":".join(sanitizer_runtimes(TILTH) + [os.environ["EARLY_THREAD_PRELOAD"]])
SECOND_SIGNAL = "second stop signal: exiting at once (code 130)"
LIBC = ctypes.CDLL(None, use_errno=True)


def default_stop_signals():
    """In the child: SIGINT and SIGTERM as an interactive shell leaves them."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)


class Tool:
    """A tool running with the early thread preloaded, its output in files."""

    def __init__(self, directory, *args):
        self.stdout_path = os.path.join(directory, "stdout.txt")
        self.stderr_path = os.path.join(directory, "stderr.txt")
        with open(self.stdout_path, "w") as out, open(self.stderr_path, "w") as err:
            self.process = subprocess.Popen(
                [TILTH, *map(str, args)], stdout=out, stderr=err,
                env=dict(os.environ, TILTH_PLUGIN_PATH=PLUGIN_PATH, LD_PRELOAD=PRELOAD),
                preexec_fn=default_stop_signals)

    def wait_for(self, condition, what, timeout=60):
        deadline = time.monotonic() + timeout
        while not condition():
            if self.process.poll() is not None:
                raise AssertionError("ended (code %d) before %s: %s" %
                                     (self.process.returncode, what, self.stderr()))
            if time.monotonic() > deadline:
                self.process.kill()
                raise AssertionError("no %s within %d s" % (what, timeout))
            time.sleep(0.02)

    def signal(self, signum):
        os.kill(self.process.pid, signum)

    def signal_thread(self, tid, signum):
        """tgkill: `signum` to one thread of the process."""
        if LIBC.tgkill(self.process.pid, tid, signum) != 0:
            raise OSError(ctypes.get_errno(), "tgkill")

    def threads(self):
        return sorted(int(tid) for tid in os.listdir("/proc/%d/task" % self.process.pid))

    def wait(self, timeout=60):
        try:
            return self.process.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()
            raise

    def stdout(self):
        with open(self.stdout_path) as f:
            return f.read()

    def stderr(self):
        with open(self.stderr_path) as f:
            return f.read()


def file_size(path):
    return os.path.getsize(path) if os.path.exists(path) else 0


def count_lines(path):
    if not os.path.exists(path):
        return 0
    with open(path, "rb") as f:
        return f.read().count(b"\n")


def whole_csv_rows(test, path):
    """The rows of a sinks.csv file, after checking each is whole and they count 0, 1, ..."""
    with open(path) as f:
        text = f.read()
    test.assertTrue(text.endswith("\n"), "last row of %s not whole: %r" % (path, text[-80:]))
    lines = text.split("\n")[:-1]
    test.assertTrue(lines[0].startswith("index,"), lines[0])
    for i, line in enumerate(lines[1:]):
        fields = line.split(",")
        test.assertEqual(len(fields), len(lines[0].split(",")), line)
        test.assertEqual(int(fields[0]), i)
        float(fields[3]), float(fields[9])  # noqa: B018 (parses)
    return len(lines) - 1


def mcap_info(test, path):
    """`tilth recording info`: (has a summary, messages on /tof/raw)."""
    info = subprocess.run([TILTH, "recording", "info", path], capture_output=True, text=True,
                          timeout=60)
    test.assertEqual(info.returncode, 0, info.stderr)
    raw = re.search(r"^  /tof/raw\s+(\d+) messages", info.stdout, re.M)
    return "summary:     yes" in info.stdout, int(raw.group(1)) if raw else 0


class Run(unittest.TestCase):
    def start(self, tmp, slow_finish_ms=None):
        self.csv = os.path.join(tmp, "run.csv")
        nodes = {"source": {"type": "testdistance.sequence", "params": {"frames": 0, "fps": 500}},
                 "csv": {"type": "sinks.csv", "params": {"path": self.csv}}}
        edges = [["source.distance", "csv.distance"]]
        if slow_finish_ms is not None:
            nodes["slow"] = {"type": "teststop.slow_finish",
                             "params": {"finish_ms": slow_finish_ms}}
            edges.append(["source.distance", "slow.distance"])
        graph = os.path.join(tmp, "graph.json")
        with open(graph, "w") as f:
            json.dump({"nodes": nodes, "edges": edges}, f)
        tool = Tool(tmp, "run", graph)
        tool.wait_for(lambda: count_lines(self.csv) > 100, "100 CSV rows")
        return tool

    def check_stopped_cleanly(self, tool):
        """Every row written before the signal (the header and 100 rows at least: start()
        waited for them) is there and whole; under load the stop may come before another."""
        self.assertEqual(tool.wait(), 0, tool.stderr())
        self.assertGreaterEqual(whole_csv_rows(self, self.csv), 100)
        self.assertIn("stopping; frames in flight finish", tool.stderr())

    def test_sigterm_stops_cleanly(self):
        with tempfile.TemporaryDirectory() as tmp:
            tool = self.start(tmp)
            tool.signal(signal.SIGTERM)
            self.check_stopped_cleanly(tool)
            self.assertIn("Terminated: stopping", tool.stderr())

    def test_sigint_stops_cleanly(self):
        with tempfile.TemporaryDirectory() as tmp:
            tool = self.start(tmp)
            tool.signal(signal.SIGINT)
            self.check_stopped_cleanly(tool)
            self.assertIn("Interrupt: stopping", tool.stderr())

    def test_sigterm_to_any_thread_stops_cleanly(self):
        """Each thread in turn: the main thread, the preloaded one, oneTBB's, the source's."""
        for index in range(4):
            with self.subTest(thread=index), tempfile.TemporaryDirectory() as tmp:
                tool = self.start(tmp)
                threads = tool.threads()
                self.assertGreater(len(threads), index)
                tool.signal_thread(threads[index], signal.SIGTERM)
                self.check_stopped_cleanly(tool)

    def test_a_second_signal_exits_at_once_with_130(self):
        with tempfile.TemporaryDirectory() as tmp:
            tool = self.start(tmp, slow_finish_ms=60000)
            tool.signal(signal.SIGTERM)
            tool.wait_for(lambda: "stopping" in tool.stderr(), "the first stop")
            sent = time.monotonic()
            tool.signal(signal.SIGINT)
            self.assertEqual(tool.wait(timeout=30), 130, tool.stderr())
            self.assertLess(time.monotonic() - sent, 5)  # not the 60 s the sink's finish takes
            self.assertIn("warning: run: " + SECOND_SIGNAL, tool.stderr())
            whole_csv_rows(self, self.csv)


class Recordings(unittest.TestCase):
    """tilth simulate, tilth recording import and export, on recordings of the quarter rig."""

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.rig = quarter_rig(cls.tmp.name)
        cls.mcap = os.path.join(cls.tmp.name, "source.mcap")
        cls.folder = os.path.join(cls.tmp.name, "source")
        for args in (["simulate", cls.mcap, "--calibration", cls.rig, "--preset", "flat",
                      "--frames", 200],
                     ["recording", "export", cls.mcap, cls.folder]):
            result = subprocess.run([TILTH, *map(str, args)], capture_output=True, text=True,
                                    timeout=600)
            assert result.returncode == 0, result.stderr

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def check_mcap_complete(self, tool, path):
        frames = re.search(r": (\d+) frames .*; stopped by a signal", tool.stdout())
        self.assertIsNotNone(frames, tool.stdout() + tool.stderr())
        has_summary, raw_messages = mcap_info(self, path)
        self.assertTrue(has_summary)
        self.assertEqual(raw_messages, int(frames.group(1)))

    def test_simulate_stops_with_a_complete_mcap(self):
        for signum in (signal.SIGTERM, signal.SIGINT):
            with self.subTest(signal=signum.name), tempfile.TemporaryDirectory() as tmp:
                output = os.path.join(tmp, "out.mcap")
                tool = Tool(tmp, "simulate", output, "--calibration", self.rig, "--preset", "flat",
                            "--frames", 100000)
                tool.wait_for(lambda: file_size(output) > 1_000_000, "a written chunk")
                tool.signal(signum)
                self.assertEqual(tool.wait(), 0, tool.stderr())
                self.check_mcap_complete(tool, output)

    def test_import_stops_with_a_complete_mcap(self):
        for signum in (signal.SIGTERM, signal.SIGINT):
            with self.subTest(signal=signum.name), tempfile.TemporaryDirectory() as tmp:
                output = os.path.join(tmp, "imported.mcap")
                tool = Tool(tmp, "recording", "import", self.folder, output)
                tool.wait_for(lambda: file_size(output) > 1_000_000, "a written chunk")
                tool.signal(signum)
                self.assertEqual(tool.wait(), 0, tool.stderr())
                self.check_mcap_complete(tool, output)

    def test_export_stops_with_a_complete_folder(self):
        for signum in (signal.SIGTERM, signal.SIGINT):
            with self.subTest(signal=signum.name), tempfile.TemporaryDirectory() as tmp:
                output = os.path.join(tmp, "exported")
                frames_csv = os.path.join(output, "frames.csv")
                tool = Tool(tmp, "recording", "export", self.mcap, output)
                tool.wait_for(lambda: count_lines(frames_csv) > 10, "10 exported frames")
                tool.signal(signum)
                self.assertEqual(tool.wait(), 0, tool.stderr())
                frames = re.search(r": (\d+) frames from .*; stopped by a signal", tool.stdout())
                self.assertIsNotNone(frames, tool.stdout() + tool.stderr())
                with open(frames_csv) as f:
                    text = f.read()
                self.assertTrue(text.endswith("\n"))
                rows = text.split("\n")[1:-1]
                self.assertEqual(len(rows), int(frames.group(1)))
                header = text.split("\n")[0].split(",")
                for row in rows:
                    fields = dict(zip(header, row.split(",")))
                    self.assertEqual(len(row.split(",")), len(header), row)
                    for column in ("depth", "color"):
                        self.assertTrue(os.path.isfile(os.path.join(output, fields[column])), row)

    def test_a_second_signal_exits_at_once_with_130(self):
        # import and export hold a scratch folder (export a calibration file in it): gone
        # too, though no destructor runs.
        scratch = os.path.join(tempfile.gettempdir(), "tilth-recording-*")
        before = set(glob.glob(scratch))
        for args, output, written in (
                (["simulate", "out.mcap", "--calibration", self.rig, "--preset", "flat",
                  "--frames", 100000], "out.mcap", lambda path: file_size(path) > 1_000_000),
                (["recording", "import", self.folder, "out.mcap"], "out.mcap",
                 lambda path: file_size(path) > 1_000_000),
                (["recording", "export", self.mcap, "out"], "out",
                 lambda path: count_lines(os.path.join(path, "frames.csv")) > 10)):
            with self.subTest(tool=" ".join(args[:2])), tempfile.TemporaryDirectory() as tmp:
                output = os.path.join(tmp, output)
                args = [output if a == os.path.basename(output) else a for a in args]
                tool = Tool(tmp, *args)
                tool.wait_for(lambda: written(output), "written output")
                tool.signal(signal.SIGTERM)
                tool.signal(signal.SIGINT)
                self.assertEqual(tool.wait(), 130, tool.stderr())
                self.assertIn(SECOND_SIGNAL, tool.stderr())
                self.assertEqual(set(glob.glob(scratch)) - before, set())

if __name__ == "__main__":
    unittest.main()

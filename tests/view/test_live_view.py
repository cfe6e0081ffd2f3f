"""view.live in graphs/simulated/seeder.json (`--var view=127.0.0.1:0`), watched by headless
Chromium: the page loads with no script error, its images change and its plot grows, the
distances it shows are the ones logged to the CSV, nothing is drawn while nobody watches,
and the run stops on SIGINT with a viewer connected. Set TILTH_VIEW_SCREENSHOT=FILE to
keep the page's screenshot (docs/images/live-view.jpg is made so)."""
import csv
import json
import os
import re
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
import unittest
import urllib.request

import cv2
import numpy as np

sys.path.insert(0, os.path.join(os.environ["TILTH_SOURCE_DIR"], "tests", "support"))
from devtools import Browser  # noqa: E402
from ports import free_port  # noqa: E402

TILTH = os.environ["TILTH_BIN"]
GRAPH = os.path.join(os.environ["TILTH_SOURCE_DIR"], "graphs", "simulated", "seeder.json")
DEMO = os.path.join(os.environ["TILTH_SOURCE_DIR"], "graphs", "demo.json")
VIEW_WIDTH = 800  # view.live's default width: two panels of 400x300 for the 640x480 depth grid
MAX_LOG_BYTES = 1_000_000


class Tilth:
    """`tilth run` of the simulated seeder with the view on a free port; its log bounded."""

    def __init__(self, work, *extra):
        self.csv = os.path.join(work, "seeder.csv")
        self.process = subprocess.Popen(
            [TILTH, "run", GRAPH, "--var", "view=127.0.0.1:0", "--var", "log=" + self.csv,
             "--set", "plc.port=%d" % free_port(), "--set", "camera.fps=10", *extra],
            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        self.lines = []
        self.url = None
        found = threading.Event()

        def read():
            size = 0
            for line in self.process.stderr:
                size += len(line)
                if size < MAX_LOG_BYTES:
                    self.lines.append(line)
                match = re.search(r"live view at (http://127\.0\.0\.1:\d+/)", line)
                if match:
                    self.url = match.group(1)
                    found.set()
            found.set()

        self.reader = threading.Thread(target=read, daemon=True)
        self.reader.start()
        found.wait(120)
        assert self.url, "no live view address in the log:\n" + "".join(self.lines)

    def get(self, path, timeout=10):
        try:
            with urllib.request.urlopen(self.url + path, timeout=timeout) as reply:
                return reply.status, dict(reply.headers), reply.read()
        except OSError as error:
            raise AssertionError("GET %s: %s\n%s" % (path, error, self.exit_report())) from error

    def exit_report(self):
        """Whether tilth run is still running, and the end of its log."""
        try:
            code = self.process.wait(2)
            state = "tilth run exited with code %d" % code
        except subprocess.TimeoutExpired:
            state = "tilth run is still running"
        return state + "; its log ends:\n" + "".join(self.lines[-40:])

    def status(self):
        return json.loads(self.get("status.json")[2])

    def stop(self, timeout=30):
        self.process.send_signal(signal.SIGINT)
        try:
            return self.process.wait(timeout)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()
            raise AssertionError("tilth run did not stop within %d s of SIGINT" % timeout)
        finally:
            self.reader.join(10)


def logged_distances(csv_path):
    with open(csv_path) as f:
        return {int(row["index"]): row for row in csv.DictReader(f)}


class LiveView(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.work = tempfile.TemporaryDirectory()
        cls.tilth = Tilth(cls.work.name)

    @classmethod
    def tearDownClass(cls):
        if cls.tilth.process.poll() is None:
            cls.tilth.stop()
        cls.work.cleanup()

    def wait_frames(self, frames):
        deadline = time.monotonic() + 120
        while self.tilth.status()["frames_completed"] < frames:
            self.assertLess(time.monotonic(), deadline, "the graph completed no frames")
            time.sleep(0.2)

    def test_1_nothing_is_drawn_while_nobody_watches(self):
        self.wait_frames(5)
        time.sleep(1.0)
        status = self.tilth.status()
        self.assertGreaterEqual(status["frames_completed"], 5)
        self.assertEqual(status["images_rendered"], 0)
        self.assertEqual(status["viewers"], 0)

    def test_2_the_page_shows_the_measurement_live(self):
        browser = Browser(self.tilth.url)
        try:
            deadline = time.monotonic() + 60
            # (the page may still be loading: no tilthView yet)
            while not browser.evaluate("!!window.tilthView && tilthView.images >= 2 &&"
                                       " tilthView.statuses >= 1"):
                self.assertLess(time.monotonic(), deadline, "the page received no images")
                time.sleep(0.2)
            # Images change, samples arrive and the plot is redrawn: three more of each (at
            # 10 frames/s in and 8 images/s out, under a second; a sanitizer build is slower).
            progress = ("({images: tilthView.images, frame: tilthView.frameId,"
                        " samples: tilthView.samples, plotted: tilthView.plotted})")
            first = browser.evaluate(progress)
            while True:
                second = browser.evaluate(progress)
                if (second["images"] - first["images"] >= 3 and second["frame"] > first["frame"]
                        and second["samples"] - first["samples"] >= 3
                        and second["plotted"] > first["plotted"]):
                    break
                self.assertLess(time.monotonic(), deadline + 60, (first, second))
                time.sleep(0.2)
            self.assertEqual(browser.evaluate("document.getElementById('image').width"), VIEW_WIDTH)
            # The canvas holds the drawn image: not the blank it starts as.
            self.assertGreater(browser.evaluate(
                "(() => { const c = document.getElementById('image');"
                " const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;"
                " let lit = 0; for (let i = 0; i < d.length; i += 4) lit += d[i] + d[i+1] + d[i+2] > 60;"
                " return lit / (d.length / 4); })()"), 0.5)
            # The distances shown are those served: every sample the page holds is the row
            # of the CSV for its frame (the CSV logs the same estimation.temporal output).
            # Read together (the page's script runs between two evaluations): the samples
            # held and the distance shown, which is the last of them.
            shown, text = browser.evaluate(
                "[JSON.stringify(tilthView.lastSamples),"
                " document.getElementById('distance').textContent]")
            shown = json.loads(shown)
            self.assertGreaterEqual(len(shown), 3)
            stages = [stage["node"] for stage in browser.evaluate("tilthView.status.stages")]
            self.assertIn("chain/estimate", stages)
            self.assertIn("view", stages)
            screenshot = os.environ.get("TILTH_VIEW_SCREENSHOT") or os.path.join(
                self.work.name, "live-view.jpg")
            browser.screenshot(screenshot)
            # On a tablet held upright the page fits its width: nothing to scroll sideways.
            browser.emulate(768, 1024, mobile=True)
            time.sleep(0.5)
            self.assertLessEqual(browser.evaluate("document.documentElement.scrollWidth"), 768)
            self.assertLessEqual(browser.evaluate(
                "document.getElementById('image').getBoundingClientRect().right"), 768)
            self.assertEqual(browser.problems(), [])
            self.assertEqual(browser.evaluate("tilthView.errors"), [])
        finally:
            browser.close()
        time.sleep(1.0)  # the CSV is flushed per row; let the last frames land
        logged = logged_distances(self.tilth.csv)
        for sample in shown:
            row = logged[sample["frame"]]
            self.assertEqual(sample["valid"], row["valid"] == "1", row)
            if sample["valid"]:
                self.assertAlmostEqual(sample["mm"], float(row["distance_mm"]), places=2)
        last = shown[-1]
        if last["valid"]:
            shown_mm = float(re.match(r"([0-9.]+) mm", text).group(1))
            self.assertLessEqual(abs(shown_mm - last["mm"]), 0.05 + 1e-9, text)  # to 0.1 mm
        # case_c lies 518 mm below the rig
        valid = [s["mm"] for s in shown if s["valid"]]
        self.assertTrue(valid)
        self.assertLess(max(abs(mm - 518.0) for mm in valid), 3.0)
        image = cv2.imread(screenshot)
        self.assertIsNotNone(image)
        self.assertEqual(image.shape[1], 1280)

    def test_3_drawing_stops_when_the_viewer_goes(self):
        time.sleep(4.0)  # a viewer counts as watching for 3 s after its last request
        before = self.tilth.status()["images_rendered"]
        time.sleep(1.5)
        after = self.tilth.status()
        self.assertEqual(after["images_rendered"], before)
        self.assertEqual(after["viewers"], 0)

    def test_4_the_mjpeg_stream_carries_whole_images(self):
        request = urllib.request.urlopen(self.tilth.url + "stream.mjpg", timeout=30)
        try:
            self.assertEqual(request.headers["Content-Type"],
                             "multipart/x-mixed-replace; boundary=tilthframe")
            images = []
            while len(images) < 2:
                self.assertEqual(request.readline().strip(), b"--tilthframe")
                headers = {}
                while True:
                    line = request.readline().strip()
                    if not line:
                        break
                    name, value = line.decode().split(":", 1)
                    headers[name.strip().lower()] = value.strip()
                self.assertEqual(headers["content-type"], "image/jpeg")
                data = request.read(int(headers["content-length"]))
                self.assertEqual(request.read(2), b"\r\n")
                images.append(cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_COLOR))
        finally:
            request.close()
        for image in images:
            self.assertEqual(image.shape, (VIEW_WIDTH * 3 // 4, VIEW_WIDTH, 3))

    def test_5_sigint_stops_the_run_with_a_viewer_connected(self):
        events = urllib.request.urlopen(self.tilth.url + "events", timeout=30)
        try:
            self.assertIn(b"event: status", events.read1(65536) + events.read1(65536))
            started = time.monotonic()
            self.assertEqual(self.tilth.stop(), 0, "".join(self.tilth.lines[-20:]))
            self.assertLess(time.monotonic() - started, 15)
        finally:
            events.close()


class ShortRun(unittest.TestCase):
    def test_a_run_of_one_frame_ends_with_its_server(self):
        # The server stops even when the run ends before it has served anything.
        for _ in range(3):
            done = subprocess.run([TILTH, "run", DEMO, "--var", "view=127.0.0.1:0", "--frames", "1"],
                                  capture_output=True, text=True, timeout=120)
            self.assertEqual(done.returncode, 0, done.stderr[-2000:])
            self.assertIn("live view at http://127.0.0.1:", done.stderr)


class Refused(unittest.TestCase):
    def run_expecting_failure(self, listen):
        done = subprocess.run([TILTH, "run", GRAPH, "--var", "view=" + listen, "--frames", "1",
                               "--set", "plc.port=%d" % free_port(), "--var", "log=/dev/null"],
                              capture_output=True, text=True, timeout=120)
        self.assertNotEqual(done.returncode, 0)
        return done.stderr

    def test_an_address_that_is_not_host_port(self):
        self.assertIn("parameter 'listen': \"localhost\" is not HOST:PORT",
                      self.run_expecting_failure("localhost"))

    def test_a_port_in_use(self):
        with socket.socket() as taken:
            taken.bind(("127.0.0.1", 0))
            taken.listen()
            port = taken.getsockname()[1]
            self.assertIn("the live view cannot listen on 127.0.0.1:%d" % port,
                          self.run_expecting_failure("127.0.0.1:%d" % port))


if __name__ == "__main__":
    unittest.main()

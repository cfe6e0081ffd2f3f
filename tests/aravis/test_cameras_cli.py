"""`tilth cameras` and a camera graph under `tilth run`, against Aravis's GigE Vision
camera simulator (arv-fake-gv-camera-0.8) on loopback addresses of their own.

The graph streams a Mono16 ToF camera and a BayerRG8 colour camera at 30 frames/s into
a test sink that prints one JSON line per frame (tests/aravis/frame_report_plugin.cpp).
After ten seconds without loss, the ToF simulator is killed and, 1.5 s later, started
again: the ToF camera's frames must lose their image and say so within two frame
periods, keep coming once per frame period, and carry images again once the simulator
is back, in the same process; the colour camera must not miss a frame meanwhile.
"""

import csv
import json
import os
import signal
import statistics
import subprocess
import sys
import tempfile
import threading
import time
import unittest

SUPPORT = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "support")
sys.path.insert(0, SUPPORT)
from fake_gige_camera import FakeCamera  # noqa: E402
from processes import interrupt, start_logged  # noqa: E402

TILTH = os.environ["TILTH_BIN"]
TEST_PLUGINS = os.environ["TILTH_TEST_PLUGIN_DIR"]


DEPTH = FakeCamera("127.0.0.21", "TILTH21")
COLOR = FakeCamera("127.0.0.22", "TILTH22")


def setUpModule():
    DEPTH.start()
    COLOR.start()


def tearDownModule():
    DEPTH.kill()
    COLOR.kill()


def table(text):
    lines = text.strip().splitlines()
    return [line.split() for line in lines]


class CamerasCommand(unittest.TestCase):
    def test_lists_every_camera_with_vendor_model_serial_and_address(self):
        done = subprocess.run([TILTH, "cameras"], capture_output=True, text=True, timeout=30)
        self.assertEqual(done.returncode, 0, done.stderr)
        rows = table(done.stdout)
        self.assertEqual(rows[0], ["VENDOR", "MODEL", "SERIAL", "ADDRESS", "DEVICE", "ID"])
        for fake in (DEPTH, COLOR):
            self.assertIn(["Aravis", "Fake", fake.serial, fake.address, "Aravis-Fake-" + fake.serial],
                          rows[1:], done.stdout)

    def test_dumps_the_features_of_one_camera_named_by_serial(self):
        done = subprocess.run([TILTH, "cameras", "--features", COLOR.serial], capture_output=True,
                              text=True, timeout=30)
        self.assertEqual(done.returncode, 0, done.stderr)
        rows = table(done.stdout)
        self.assertEqual(rows[0], ["FEATURE", "TYPE", "VALUE", "ACCESS"])
        for row in (["ImageFormatControl", "Category"], ["Width", "Integer", "512", "RW"],
                    ["DeviceID", "StringReg", COLOR.serial, "RO"],
                    ["AcquisitionStart", "Command", "WO"]):
            self.assertIn(row, rows, done.stdout)
        pixel_format = next(row for row in rows if row[0] == "PixelFormat")
        self.assertEqual(pixel_format[1::2], ["Enumeration", "RW"])

    def test_a_camera_that_is_not_there_is_a_clear_error(self):
        done = subprocess.run([TILTH, "cameras", "--features", "NO-SUCH-CAMERA"],
                              capture_output=True, text=True, timeout=30)
        self.assertEqual(done.returncode, 1)
        self.assertIn("no GigE Vision camera with device id, serial number or MAC address "
                      "'NO-SUCH-CAMERA'", done.stderr)


GRAPH = {
    "description": "Two simulated cameras into frame reports.",
    "nodes": {
        "depth": {"type": "aravis.tof_camera",
                  "params": {"camera": DEPTH.address, "pixel_format": "Mono16", "frame_rate": 30,
                             "packet_socket": False}},
        "color": {"type": "aravis.color_camera",
                  "params": {"camera": COLOR.address, "pixel_format": "BayerRG8",
                             "frame_rate": 30, "packet_socket": False}},
        "depth_report": {"type": "aravistest.frame_report", "params": {"label": "depth"}},
        "color_report": {"type": "aravistest.frame_report", "params": {"label": "color"}},
    },
    "edges": [
        ["depth.raw", "depth_report.image"], ["depth.status", "depth_report.status"],
        ["color.color", "color_report.image"], ["color.status", "color_report.status"],
    ],
    # Block, not drop: the test counts the camera's frames, not the runtime's choices.
    "runtime": {"max_in_flight": 4, "when_full": "block", "on_error": "skip"},
}


class CameraGraph(unittest.TestCase):
    def test_streams_two_cameras_without_loss_and_survives_a_camera_going_away(self):
        with tempfile.TemporaryDirectory() as directory:
            graph = os.path.join(directory, "cameras.json")
            with open(graph, "w") as out:
                json.dump(GRAPH, out)
            env = dict(os.environ, TILTH_PLUGIN_PATH=TEST_PLUGINS)
            with open(os.path.join(directory, "stderr.txt"), "w+") as log:
                run = subprocess.Popen([TILTH, "run", graph], stdout=subprocess.PIPE, stderr=log,
                                       text=True, env=env)
                lines, unreadable = [], []

                def read():
                    for text in run.stdout:
                        try:
                            lines.append(json.loads(text))
                        except ValueError:
                            unreadable.append(text)

                reader = threading.Thread(target=read)
                reader.start()
                try:
                    self.wait_for(lines, lambda l: l["label"] == "depth" and l["image"], 10)
                    time.sleep(10.5)
                    killed_ns = time.time_ns()
                    DEPTH.kill()
                    time.sleep(1.5)
                    restarted_ns = time.time_ns()
                    DEPTH.start()
                    self.wait_for(lines, lambda l: l["label"] == "depth" and l["image"] and
                                  l["host_ns"] > restarted_ns, 10)
                    time.sleep(1.0)
                finally:
                    run.send_signal(signal.SIGINT)
                    code = run.wait(timeout=20)
                    reader.join()
                    run.stdout.close()
                    log.seek(0)
                    stderr = log.read()
            self.assertEqual(code, 0, stderr)
            self.assertEqual(unreadable, [])

        depth = [l for l in lines if l["label"] == "depth"]
        color = [l for l in lines if l["label"] == "color"]

        # Ten seconds without loss on both cameras.
        longest_gap_ms = 0.0  # between two images, on either clock: the longest pause
        for name, frames, check in (("depth", depth, lambda i: i["format"] == "raw"),
                                    ("color", color, lambda i: i["format"] == "bayer_rggb8")):
            first = next(i for i, l in enumerate(frames) if l["image"])
            window = [l for l in frames[first:] if l["host_ns"] < killed_ns]
            with self.subTest(camera=name):
                images = [l for l in window if l["image"]]
                seconds = (images[-1]["device_ns"] - images[0]["device_ns"]) / 1e9
                period_ms = statistics.median((b["device_ns"] - a["device_ns"]) / 1e6
                                              for a, b in zip(images, images[1:]))
                print("%s: %d frames in %.2f s (%.2f frames/s; every %.2f ms at the median), "
                      "%d lost, %d incomplete, %d late" %
                      (name, len(images), seconds, (len(images) - 1) / seconds, period_ms,
                       window[-1]["lost"], window[-1]["incomplete"], window[-1]["late"]))
                # Every frame the simulator sent is passed on. A frame without image comes
                # only after two periods in which none arrived (less 10 ms of jitter): the
                # simulator paused (its own clock shows it) or this machine did (the frames'
                # host times show it). A frame the simulator paused in the middle of comes
                # incomplete (Aravis waits 100 ms for its missing packets).
                skipped = 0
                for before, after in zip(images, images[1:]):
                    paused_ms = (after["device_ns"] - before["device_ns"]) / 1e6
                    host_gap_ms = (after["host_ns"] - before["host_ns"]) / 1e6
                    longest_gap_ms = max(longest_gap_ms, paused_ms, host_gap_ms)
                    missing = (after["frame_id"] - before["frame_id"] - 1) % 65535
                    # (host_ns is when a frame's first packet came; allow 10 ms for the rest)
                    empty = [l for l in window if not l["image"] and
                             before["host_ns"] + 10e6 < l["host_ns"] <= after["host_ns"] + 10e6]
                    if missing or empty:
                        print("%s: %.0f ms between two images on the simulator's clock, %.0f ms "
                              "on the host's: %d frames without image, %d incomplete" %
                              (name, paused_ms, host_gap_ms, len(empty), missing))
                        self.assertGreater(paused_ms, (missing + 1) * 1000 / 30 - 10)
                        if empty:
                            self.assertGreater(host_gap_ms, 2 * 1000 / 30 - 10)
                        self.assertTrue(all(not l["streaming"] for l in empty))
                    skipped += missing
                self.assertTrue(all(check(l["image"]) and l["image"]["test_image"] for l in images))
                self.assertEqual(window[-1]["incomplete"] - images[0]["incomplete"], skipped)
                self.assertGreaterEqual(seconds, 10.0)
                self.assertAlmostEqual(period_ms, 1000 / 30, delta=0.3)
                self.assertEqual(window[-1]["lost"], 0)
                self.assertEqual(window[-1]["late"], 0)

        # The ToF camera goes invalid two frame periods after its last frame, and a loaded
        # machine may be late by as long as it paused before; at least 80 ms is allowed (under
        # ASan on the 2-core VM the loss was seen 135 ms after the last frame of a run without
        # pauses) ...
        gone = [l for l in depth if l["host_ns"] > killed_ns and not l["image"]]
        self.assertTrue(gone)
        last = max(l["host_ns"] for l in depth if l["image"] and l["host_ns"] < killed_ns)
        detect_ms = (gone[0]["host_ns"] - last) / 1e6
        back = next(l for l in depth if l["host_ns"] > restarted_ns and l["image"])
        while_lost = [l for l in gone if l["host_ns"] < back["host_ns"]]
        gaps = [(b["host_ns"] - a["host_ns"]) / 1e6 for a, b in zip(while_lost, while_lost[1:])]
        resume_ms = (back["host_ns"] - restarted_ns) / 1e6
        print("depth killed: invalid %.0f ms after its last frame, then a frame every %.1f ms "
              "(max %.1f); streaming again %.0f ms after the restart" %
              (detect_ms, statistics.median(gaps), max(gaps), resume_ms))
        self.assertLess(detect_ms, 2 * 1000 / 30 + max(80, longest_gap_ms))
        self.assertTrue(all(not l["streaming"] and l["problem"] for l in while_lost))
        self.assertAlmostEqual(statistics.median(gaps), 33.3, delta=3)
        self.assertLess(max(gaps), 1000 / 30 + max(25, longest_gap_ms))
        # ... and streams again in the same process once it is back.
        self.assertLess(resume_ms, 5000)
        resumed = [l for l in depth if l["host_ns"] >= back["host_ns"] and l["image"]]
        self.assertTrue(all(l["image"]["test_image"] and l["streaming"] for l in resumed))
        self.assertGreaterEqual(len(resumed), 25)

        # The colour camera did not notice.
        self.assertEqual(color[-1]["lost"] + color[-1]["late"], 0)
        self.assertTrue(all(l["image"]["test_image"] for l in color if l["image"]))

    def wait_for(self, lines, predicate, seconds):
        deadline = time.monotonic() + seconds
        while not any(predicate(l) for l in list(lines)):
            self.assertLess(time.monotonic(), deadline, "timed out waiting for a frame")
            time.sleep(0.02)




class FakeCamerasGraph(unittest.TestCase):
    """graphs/fake-cameras.json: both simulators through pairing and the whole measurement
    chain. Their test pattern is no field scene: frames, pairing and timing are checked,
    not the distance."""

    def test_runs_the_measurement_chain_on_two_simulated_cameras(self):
        graph = os.path.join(os.environ["TILTH_SOURCE_DIR"], "graphs", "fake-cameras.json")
        with tempfile.TemporaryDirectory() as directory:
            rows_path = os.path.join(directory, "rows.csv")
            with open(os.path.join(directory, "stderr.txt"), "w+") as log:
                run = subprocess.Popen(
                    [TILTH, "run", graph, "--var", "depth_camera=" + DEPTH.address,
                     "--var", "color_camera=" + COLOR.address, "--var", "log=" + rows_path],
                    stdout=subprocess.DEVNULL, stderr=log)
                time.sleep(8)
                run.send_signal(signal.SIGINT)
                code = run.wait(timeout=30)
                log.seek(0)
                stderr = log.read()
            self.assertEqual(code, 0, stderr)
            with open(rows_path, newline="") as f:
                rows = list(csv.DictReader(f))
        # 30 pairs/s for the ~6 s after the cameras open; the chain drops the oldest when
        # the shared cores fall behind, so at least half must come through.
        self.assertGreaterEqual(len(rows), 90, stderr)
        ids = [int(row["index"]) for row in rows]
        # One row per depth frame, in order: block ids advance (16 bits, 0 skipped).
        steps = [(b - a) % 65535 for a, b in zip(ids, ids[1:])]
        self.assertTrue(all(0 < step < 100 for step in steps), ids)
        host = [int(row["host_timestamp_ns"]) for row in rows]
        gaps_ms = [(b - a) / 1e6 / step for a, b, step in zip(host, host[1:], steps)]
        # One depth frame every 33.3 ms on the host clock, paired or not.
        self.assertAlmostEqual(statistics.median(gaps_ms), 33.3, delta=3.0)
        self.assertIn("pairs; unmatched and dropped:", stderr)
        # The colour camera's window of its sensor, registered with that window's
        # calibration: no frame refused for its size.
        self.assertIn("chain/register: colour images are a window of the sensor: registering "
                      "with ", stderr)
        self.assertIn("paper_rig.calib.json, colour window 736x512 px at (368, 256)", stderr)
        register = [line.split() for line in stderr.splitlines()
                    if line.startswith("chain/register ")]
        self.assertEqual(len(register), 1, stderr)
        self.assertEqual(register[0][-2], "0", stderr)  # errors


class FakeCamerasGraphOnAScene(unittest.TestCase):
    """graphs/fake-cameras.json on two simulators that show a scene rendered by `tilth
    simulate` (case_c, 518 mm, with its colour as a BayerRG8 mosaic): the distance that
    comes out of the live cameras is the scene's."""

    def test_measures_the_scene_the_cameras_show(self):
        graph = os.path.join(os.environ["TILTH_SOURCE_DIR"], "graphs", "fake-cameras.json")
        with tempfile.TemporaryDirectory() as directory:
            scene = os.path.join(directory, "scene")
            subprocess.run([TILTH, "simulate", scene, "--preset", "case_c", "--frames", "1",
                            "--color-format", "bayer_rggb8"], check=True, timeout=60,
                           stdout=subprocess.DEVNULL)
            with open(os.path.join(scene, "frames.csv"), newline="") as f:
                truth_mm = float(next(csv.DictReader(f))["ground_truth_mm"])
            depth = FakeCamera("127.0.0.23", "TILTH23",
                               image=os.path.join(scene, "depth", "000000.png"))
            color = FakeCamera("127.0.0.24", "TILTH24",
                               image=os.path.join(scene, "color", "000000.png"))
            rows_path = os.path.join(directory, "rows.csv")
            log_path = os.path.join(directory, "stderr.txt")
            run = None
            try:
                depth.start()
                color.start()
                run = start_logged(
                    [TILTH, "run", graph, "--var", "depth_camera=" + depth.address,
                     "--var", "color_camera=" + color.address, "--var", "log=" + rows_path],
                    log_path)
                time.sleep(6)
            finally:
                interrupt(run)
                depth.kill()
                color.kill()
            with open(log_path) as log:
                stderr = log.read()
            self.assertEqual(run.returncode, 0, stderr)
            with open(rows_path, newline="") as f:
                measured = list(csv.DictReader(f))
        self.assertGreaterEqual(len(measured), 60, stderr)
        self.assertTrue(all(row["valid"] == "1" for row in measured), measured[:5])
        # Every pair shows the same frame: within the static scenes' bound (docs/accuracy.md).
        for row in measured:
            self.assertAlmostEqual(float(row["distance_mm"]), truth_mm, delta=0.5)


if __name__ == "__main__":
    unittest.main()

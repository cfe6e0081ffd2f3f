"""`tilth calibrate capture` live, against two of Aravis's GigE Vision camera simulators
(arv-fake-gv-camera-0.8) on loopback addresses of their own: the ToF camera is asked for
its Intensity component in Mono16 (the simulator has no components and streams its image
as it is), the colour camera streams as it is, and the pairs are matched by capture time.
The simulators' test pattern holds no board: pairs are looked at, none is kept, nothing
is written, exit 5; a stop signal ends it cleanly; a camera that is not there is named.
"""

import os
import signal
import subprocess
import sys
import tempfile
import time
import unittest

SUPPORT = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "support")
sys.path.insert(0, SUPPORT)
from fake_gige_camera import FakeCamera  # noqa: E402

TILTH = os.environ["TILTH_BIN"]

TOF = FakeCamera("127.0.0.23", "TILTH23")
COLOR = FakeCamera("127.0.0.24", "TILTH24")
# The simulators answer on their own addresses only: no packet socket (docs/cameras.md).
SIMULATOR_SETTINGS = ["--set", "tof.packet_socket=false", "--set", "color.packet_socket=false"]


def setUpModule():
    TOF.start()
    COLOR.start()


def tearDownModule():
    TOF.kill()
    COLOR.kill()


def capture(out, *options):
    return [TILTH, "calibrate", "capture", "--tof", TOF.address, "--color", COLOR.address,
            "--board", "8x5", "--out", out] + SIMULATOR_SETTINGS + list(options)


class LiveCapture(unittest.TestCase):
    def test_looks_at_live_pairs_and_keeps_none_without_a_board(self):
        with tempfile.TemporaryDirectory() as directory:
            out = os.path.join(directory, "views")
            done = subprocess.run(capture(out, "--frames", "20"), capture_output=True, text=True,
                                  timeout=60)
            self.assertEqual(done.returncode, 5, done.stdout + done.stderr)
            self.assertIn("board not found in either image", done.stdout)
            self.assertRegex(done.stdout, out + r": 0 views kept from [1-9][0-9]* frame pairs "
                             r"\(the board in both images in 0\)")
            self.assertIn("fewer views than solve needs (6)", done.stdout)
            self.assertFalse(os.path.exists(out))
            # The ToF camera was asked for its intensity; the simulator has no components.
            self.assertIn("has no components (ComponentSelector)", done.stderr)

    def test_a_stop_signal_ends_it_cleanly(self):
        with tempfile.TemporaryDirectory() as directory:
            out = os.path.join(directory, "views")
            run = subprocess.Popen(capture(out), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                   text=True)
            try:
                # Pairs are being looked at once the first verdict is printed.
                first = run.stdout.readline()
                self.assertIn("board not found", first)
                time.sleep(1.0)
            finally:
                run.send_signal(signal.SIGTERM)
                try:
                    rest, stderr = run.communicate(timeout=20)
                except subprocess.TimeoutExpired:
                    run.kill()
                    run.communicate()
                    raise
            self.assertEqual(run.returncode, 5, rest + stderr)
            self.assertRegex(rest, r"0 views kept from [1-9][0-9]* frame pairs .*; stopped")

    def test_a_camera_that_is_not_there_is_named(self):
        with tempfile.TemporaryDirectory() as directory:
            out = os.path.join(directory, "views")
            done = subprocess.run(
                [TILTH, "calibrate", "capture", "--tof", "127.0.0.99", "--color", COLOR.address,
                 "--board", "8x5", "--out", out] + SIMULATOR_SETTINGS,
                capture_output=True, text=True, timeout=60)
            self.assertEqual(done.returncode, 1, done.stdout + done.stderr)
            self.assertIn("node 'tof' (aravis.tof_camera) failed to start", done.stderr)
            self.assertIn("127.0.0.99", done.stderr)
            self.assertFalse(os.path.exists(out))


if __name__ == "__main__":
    unittest.main()

"""`tilth run` as systemd runs a Type=notify service: the notifications arrive on a real
datagram socket named by NOTIFY_SOCKET, as systemd's manager receives them. READY=1 comes
once frames pass the graph, WATCHDOG=1 only while frames keep completing (a paused source
feeds no watchdog), STATUS= lines say how the run goes, STOPPING=1 follows SIGTERM."""
import os
import signal
import socket
import subprocess
import tempfile
import time
import unittest

TILTH = os.environ["TILTH_BIN"]
SOURCE = os.environ["TILTH_SOURCE_DIR"]


DEMO = os.path.join(SOURCE, "graphs", "demo.json")


def demo(fps):
    """The demo graph with its scene paced at `fps`, printing nothing."""
    return [DEMO, "--set", f"camera.fps={fps}", "--set", "print.every=1000000"]


class Service:
    """tilth run with NOTIFY_SOCKET and WATCHDOG_USEC set, as systemd starts it."""

    def __init__(self, directory, graph_args, watchdog_ms):
        self.socket_path = os.path.join(directory, "notify.sock")
        self.socket = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
        self.socket.bind(self.socket_path)
        self.socket.settimeout(0.05)
        self.messages = []  # (seconds since start, message)
        self.start = time.monotonic()
        self.log = open(os.path.join(directory, "stderr.txt"), "w+")
        env = dict(os.environ, NOTIFY_SOCKET=self.socket_path,
                   WATCHDOG_USEC=str(watchdog_ms * 1000))
        self.process = subprocess.Popen([TILTH, "run", *graph_args], stdout=subprocess.DEVNULL,
                                        stderr=self.log, env=env)

    def receive_for(self, seconds):
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            try:
                data = self.socket.recv(4096).decode()
            except socket.timeout:
                continue
            self.messages.append((time.monotonic() - self.start, data))

    def receive_until_ready(self, timeout=60):
        deadline = time.monotonic() + timeout
        while not self.times("READY=1") and time.monotonic() < deadline:
            self.receive_for(0.05)

    def lines(self):
        return [(t, line) for t, message in self.messages for line in message.splitlines()]

    def times(self, key):
        return [t for t, line in self.lines() if line == key]

    def finish(self):
        self.process.send_signal(signal.SIGTERM)
        try:
            code = self.process.wait(timeout=30)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()
            raise
        self.receive_for(0.3)
        self.socket.close()
        self.log.seek(0)
        stderr = self.log.read()[-4000:]
        self.log.close()
        return code, stderr


class Notifications(unittest.TestCase):
    def test_ready_watchdog_and_stopping_while_frames_flow(self):
        with tempfile.TemporaryDirectory() as directory:
            service = Service(directory, demo(20), watchdog_ms=1000)
            try:
                service.receive_until_ready()
                service.receive_for(3.0)
            finally:
                code, stderr = service.finish()
            self.assertEqual(code, 0, stderr)
            ready = service.times("READY=1")
            self.assertEqual(len(ready), 1, service.messages)
            watchdog = service.times("WATCHDOG=1")
            # Every half of the watchdog's second while frames complete: about 6 in the 3 s
            # after readiness. Never a second without one, which would have systemd kill a
            # graph whose frames flow (a ping waits for a completed frame: under ASan on a
            # loaded machine, frames at 20/s have stalled 400 ms).
            self.assertGreaterEqual(len(watchdog), 4, service.messages)
            self.assertTrue(all(t > ready[0] for t in watchdog))
            self.assertLess(max(b - a for a, b in zip(watchdog, watchdog[1:])), 1.0)
            self.assertTrue(any(line.startswith("STATUS=frames ") for _, line in service.lines()),
                            service.messages)
            stopping = service.times("STOPPING=1")
            self.assertEqual(len(stopping), 1, service.messages)
            self.assertGreater(stopping[0], watchdog[-1])

    def test_no_watchdog_while_no_frame_completes(self):
        # A frame every 2 s: between frames, the 300 ms watchdog gets no ping; the status
        # says how long the graph has been silent.
        with tempfile.TemporaryDirectory() as directory:
            service = Service(directory, demo(0.5), watchdog_ms=300)
            try:
                service.receive_until_ready()
                service.receive_for(4.5)
            finally:
                code, stderr = service.finish()
            self.assertEqual(code, 0, stderr)
            ready = service.times("READY=1")
            self.assertEqual(len(ready), 1, service.messages)
            watchdog = service.times("WATCHDOG=1")
            # Frames about 2 and 4 s after the one that made it ready: a ping each.
            self.assertIn(len(watchdog), [1, 2], service.messages)
            self.assertGreater(min(b - a for a, b in zip(ready + watchdog, watchdog)), 1.5)
            silent = [line for _, line in service.lines()
                      if line.startswith("STATUS=no frame completed for")]
            self.assertGreaterEqual(len(silent), 8, service.messages)

    def test_outside_systemd_nothing_is_sent(self):
        with tempfile.TemporaryDirectory() as directory:
            result = subprocess.run([TILTH, "run", *demo(0), "--frames", "3"],
                                    capture_output=True, text=True, timeout=60,
                                    env={k: v for k, v in os.environ.items()
                                         if k != "NOTIFY_SOCKET"})
            self.assertEqual(result.returncode, 0, result.stderr)
            self.assertNotIn("notify", result.stderr)


if __name__ == "__main__":
    unittest.main()

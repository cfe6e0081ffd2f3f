"""Aravis's GigE Vision camera simulator (arv-fake-gv-camera-0.8) on a loopback address
of its own, started and killed by its pid. With trigger_checks_hz or image, the
simulator is tilth-fake-gige-camera (its path in TILTH_FAKE_CAMERA), which looks for a
software trigger that many times a second instead of arv-fake-gv-camera's 25, and shows
that PNG (a rendered scene: a recording's depth or colour frame) instead of its test
pattern."""
import os
import socket
import struct
import subprocess
import time

GVCP_PORT = 3956


def udp_bound(address, port):
    wanted = "%08X:%04X" % (struct.unpack("<I", socket.inet_aton(address))[0], port)
    with open("/proc/net/udp") as table:
        return any(wanted in line for line in table)


class FakeCamera:
    def __init__(self, address, serial, trigger_checks_hz=None, image=None):
        self.address, self.serial, self.process = address, serial, None
        self.trigger_checks_hz, self.image = trigger_checks_hz, image
        shown = subprocess.run(["ip", "-o", "addr", "show", "dev", "lo"], capture_output=True,
                               text=True, check=True).stdout
        if " inet %s/" % address not in shown:
            subprocess.run(["ip", "addr", "add", address + "/8", "dev", "lo"], check=True)

    def start(self):
        assert not udp_bound(self.address, GVCP_PORT), "a device already listens on " + self.address
        # At a higher priority than the tests: the simulator plays a camera, which has a
        # processor of its own.
        if self.trigger_checks_hz or self.image:
            simulator = [os.environ["TILTH_FAKE_CAMERA"], self.address, self.serial]
            if self.trigger_checks_hz:
                simulator += ["--trigger-checks-hz", str(self.trigger_checks_hz)]
            if self.image:
                simulator += ["--image", self.image]
        else:
            simulator = ["arv-fake-gv-camera-0.8", "-i", self.address, "-s", self.serial]
        self.process = subprocess.Popen(["nice", "-n", "-10"] + simulator,
                                        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        deadline = time.monotonic() + 5
        while not udp_bound(self.address, GVCP_PORT):
            assert time.monotonic() < deadline, "the simulator did not start on " + self.address
            time.sleep(0.01)

    def kill(self):
        if self.process:
            self.process.kill()
            self.process.wait()
            self.process = None

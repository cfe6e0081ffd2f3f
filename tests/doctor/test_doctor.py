"""`tilth doctor` against Aravis's GigE Vision camera simulator behind a network of its
own: two simulated cameras in a network namespace (10.77.0.11, .12), joined to this host by
a veth pair (10.77.0.1/24), as cameras on a NIC; a real Modbus TCP server (pymodbus) as the
PLC. Then the failures the test can cause: an MTU below the cameras' packet size, packet
loss (nftables dropping 1 in 20 of the cameras' stream packets), a closed PLC port, a
camera that is not there, addresses off the host's subnets or the host's own, too little
free disk."""
import json
import os
import signal
import subprocess
import sys
import tempfile
import time
import unittest

SUPPORT = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "support")
sys.path.insert(0, SUPPORT)
from ports import free_port, wait_for_port  # noqa: E402

TILTH = os.environ["TILTH_BIN"]
NAMESPACE = "tilth-doctor-test"
NETNS_DIR = "/run/netns"
HOST_SIDE, CAMERA_SIDE = "tdoctor0", "tdoctor1"
HOST_ADDRESS = "10.77.0.1"
CAMERAS = ["10.77.0.11", "10.77.0.12"]
FRAME_BYTES = 512 * 512  # the simulator's Mono8 frame


def sh(*args, check=True):
    return subprocess.run(list(args), capture_output=True, text=True, check=check)


def in_namespace(*args, check=True):
    # nsenter enters only the network namespace: `ip netns exec` also remounts /sys, which
    # a chroot (a clean root's test run) refuses.
    return sh("nsenter", "--net=" + os.path.join(NETNS_DIR, NAMESPACE), *args, check=check)


def set_mtu(mtu):
    sh("ip", "link", "set", HOST_SIDE, "mtu", str(mtu))
    in_namespace("ip", "link", "set", CAMERA_SIDE, "mtu", str(mtu))


class Doctor(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.netns_was_mounted = os.path.ismount(NETNS_DIR)
        sh("ip", "netns", "del", NAMESPACE, check=False)  # left by a killed run
        sh("ip", "link", "del", HOST_SIDE, check=False)
        sh("ip", "netns", "add", NAMESPACE)
        sh("ip", "link", "add", HOST_SIDE, "type", "veth", "peer", "name", CAMERA_SIDE)
        sh("ip", "link", "set", CAMERA_SIDE, "netns", NAMESPACE)
        sh("ip", "addr", "add", HOST_ADDRESS + "/24", "dev", HOST_SIDE)
        sh("ip", "link", "set", HOST_SIDE, "up")
        for address in CAMERAS:
            in_namespace("ip", "addr", "add", address + "/24", "dev", CAMERA_SIDE)
        in_namespace("ip", "link", "set", CAMERA_SIDE, "up")
        in_namespace("ip", "link", "set", "lo", "up")
        # At a higher priority than the tests beside them: each simulator plays a camera,
        # which has a processor of its own; starved, it sends frames too late to be whole.
        cls.cameras = [subprocess.Popen(
            ["nice", "-n", "-10", "nsenter", "--net=" + os.path.join(NETNS_DIR, NAMESPACE),
             "arv-fake-gv-camera-0.8", "-i", address,
             "-s", "DOCTOR%d" % i], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            for i, address in enumerate(CAMERAS)]
        cls.plc_port = free_port()
        cls.plc = subprocess.Popen([sys.executable, os.path.join(SUPPORT, "plc_server.py"),
                                    str(cls.plc_port)],
                                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        wait_for_port(cls.plc_port)
        deadline = time.monotonic() + 10
        while True:
            listening = in_namespace("ss", "-uln").stdout
            if all(address + ":3956" in listening for address in CAMERAS):
                break
            assert time.monotonic() < deadline, "the camera simulators did not start"
            time.sleep(0.05)

    @classmethod
    def tearDownClass(cls):
        for process in cls.cameras + [cls.plc]:
            process.send_signal(signal.SIGKILL)
            process.wait()
        sh("ip", "netns", "del", NAMESPACE, check=False)
        sh("ip", "link", "del", HOST_SIDE, check=False)
        # `ip netns add` bind-mounts /run/netns onto itself; leave the machine as found, or a
        # chroot this ran in cannot be removed.
        if not cls.netns_was_mounted and not os.listdir(NETNS_DIR):
            sh("umount", NETNS_DIR, check=False)

    def doctor(self, *args):
        done = subprocess.run([TILTH, "doctor", "--seconds", "2", *args, "--json"],
                              capture_output=True, text=True, timeout=120)
        self.assertIn(done.returncode, (0, 1), done.stderr)
        report = json.loads(done.stdout)
        self.assertEqual(report["ok"], done.returncode == 0)
        return done.returncode, {check["check"]: check for check in report["checks"]}

    def cameras_args(self):
        return [arg for address in CAMERAS for arg in ("--camera", address)]

    def test_a_healthy_machine(self):
        with tempfile.TemporaryDirectory() as recordings:
            code, checks = self.doctor(*self.cameras_args(), "--plc",
                                       "127.0.0.1:%d" % self.plc_port, "--recordings",
                                       recordings, "--min-free-gb", "0")
        failed = [c for c in checks.values() if c["verdict"] == "failed"]
        self.assertEqual((code, failed), (0, []))
        for address in CAMERAS:
            self.assertEqual(checks[f"camera {address}: address"]["detail"],
                             f"on {HOST_SIDE} ({HOST_ADDRESS})")
            # 1400-byte packets fit the veth's 1500, without jumbo frames: a warning.
            packet = checks[f"camera {address}: packet size"]
            self.assertEqual(packet["verdict"], "warning")
            self.assertEqual(packet["detail"].split(":")[0],
                             f"1400 bytes, MTU of {HOST_SIDE} 1500")
            streaming = checks[f"camera {address}: streaming"]
            self.assertEqual(streaming["verdict"], "ok")
            frames = int(streaming["detail"].split()[0])
            # The simulator's 25 frames/s for 2 s, less start-up.
            self.assertGreaterEqual(frames, 30, streaming["detail"])
            self.assertIn("0 incomplete, 0 packets missing", streaming["detail"])
        self.assertEqual(checks["camera clocks"]["verdict"], "ok")
        self.assertIn("no PTP", checks["camera clocks"]["detail"])
        self.assertEqual(checks[f"PLC 127.0.0.1:{self.plc_port}"]["verdict"], "ok")
        with open("/proc/sys/net/core/rmem_max") as f:
            rmem_max = int(f.read())
        rmem = checks["net.core.rmem_max"]
        self.assertEqual(rmem["verdict"], "ok" if rmem_max >= FRAME_BYTES else "warning")
        self.assertIn(f"the largest frame is {FRAME_BYTES} bytes", rmem["detail"])

    def test_discovery_finds_both_cameras(self):
        done = subprocess.run([TILTH, "doctor", "--seconds", "1"], capture_output=True,
                              text=True, timeout=120)
        first = done.stdout.splitlines()[0]
        for i, address in enumerate(CAMERAS):
            self.assertIn(f"(serial DOCTOR{i}) at {address}", first)
        for address in CAMERAS:
            self.assertIn(f"camera {address}: streaming", done.stdout)

    def test_packets_larger_than_the_mtu_fail(self):
        set_mtu(1000)
        try:
            code, checks = self.doctor("--camera", CAMERAS[0], "--min-free-gb", "0")
        finally:
            set_mtu(1500)
        self.assertEqual(code, 1)
        packet = checks[f"camera {CAMERAS[0]}: packet size"]
        self.assertEqual(packet["verdict"], "failed")
        self.assertIn(f"1400 bytes, MTU of {HOST_SIDE} 1000", packet["detail"])
        self.assertIn(f"ip link set {HOST_SIDE} mtu 9000", packet["fix"])

    def test_lost_packets_fail(self):
        in_namespace("nft", "add", "table", "ip", "doctor_test")
        in_namespace("nft", "add chain ip doctor_test out { type filter hook output priority 0 ; }")
        in_namespace("nft", "add rule ip doctor_test out udp sport != 3956 numgen random mod 20 == 0 drop")
        try:
            code, checks = self.doctor("--camera", CAMERAS[0], "--min-free-gb", "0")
        finally:
            in_namespace("nft", "delete", "table", "ip", "doctor_test")
        self.assertEqual(code, 1)
        streaming = checks[f"camera {CAMERAS[0]}: streaming"]
        self.assertEqual(streaming["verdict"], "failed")
        missing = int(streaming["detail"].split(" packets missing")[0].split()[-1])
        self.assertGreater(missing, 0, streaming["detail"])
        self.assertIn("net.core.rmem_max", streaming["fix"])

    def test_what_is_not_there_fails(self):
        closed = free_port()
        code, checks = self.doctor("--camera", "10.77.0.99", "--plc", f"127.0.0.1:{closed}",
                                   "--min-free-gb", "1000000")
        self.assertEqual(code, 1)
        self.assertEqual(checks["camera 10.77.0.99: control"]["verdict"], "failed")
        plc = checks[f"PLC 127.0.0.1:{closed}"]
        self.assertEqual(plc["verdict"], "failed")
        self.assertIn("Connection refused", plc["detail"])
        self.assertEqual(checks["free disk"]["verdict"], "failed")
        self.assertIn("wanted 1024000000 MiB", checks["free disk"]["detail"])

    def test_addresses_off_the_subnet_or_the_hosts_own_fail(self):
        code, checks = self.doctor("--camera", "10.78.0.5", "--camera", HOST_ADDRESS,
                                   "--seconds", "1", "--min-free-gb", "0")
        self.assertEqual(code, 1)
        off = checks["camera 10.78.0.5: address"]
        self.assertEqual((off["verdict"], off["detail"]),
                         ("failed", "on no subnet of this host's interfaces"))
        own = checks[f"camera {HOST_ADDRESS}: address"]
        self.assertEqual(own["verdict"], "failed")
        self.assertIn(f"the host's own interface {HOST_SIDE} has this address", own["detail"])

    def test_text_lines_and_usage(self):
        done = subprocess.run([TILTH, "doctor", "--camera", CAMERAS[0], "--seconds", "1",
                               "--min-free-gb", "0"], capture_output=True, text=True, timeout=120)
        lines = done.stdout.splitlines()
        self.assertTrue(all(line[:4] in ("ok  ", "WARN", "FAIL") for line in lines), lines)
        self.assertIn(f"ok    camera {CAMERAS[0]}: streaming:", done.stdout)
        bad = subprocess.run([TILTH, "doctor", "--seconds", "0"], capture_output=True, text=True)
        self.assertEqual(bad.returncode, 2)
        self.assertIn("--seconds", bad.stderr)


if __name__ == "__main__":
    unittest.main()

"""`tilth run` as a service whose standard error systemd connected to the journal
(JOURNAL_STREAM): its log lines reach the journal's native socket as entries with
PRIORITY= and TILTH_NODE=. Runs itself again in a mount namespace of its own (unshare)
with a tmpfs over /run/systemd/journal, where this test binds the socket that journald
would. Where no private mount namespace can be made (a chroot whose root is no mount
point), it says why and exits 77, which ctest counts as skipped."""
import os
import socket
import struct
import subprocess
import sys
import tempfile
import unittest

TILTH = os.environ["TILTH_BIN"]
DEMO = os.path.join(os.environ["TILTH_SOURCE_DIR"], "graphs", "demo.json")
JOURNAL = "/run/systemd/journal"


def parse_entry(datagram):
    """The journal's native protocol: KEY=value lines, or KEY, a 64-bit little-endian
    length and the value, for values holding a newline."""
    fields, i = {}, 0
    while i < len(datagram):
        end = datagram.index(b"\n", i)
        line = datagram[i:end]
        if b"=" in line:
            key, value = line.split(b"=", 1)
            i = end + 1
        else:
            key = line
            (size,) = struct.unpack_from("<Q", datagram, end + 1)
            value = datagram[end + 9:end + 9 + size]
            i = end + 9 + size + 1
        fields[key.decode()] = value.decode()
    return fields


class JournalEntries(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        os.makedirs(JOURNAL, exist_ok=True)
        subprocess.run(["mount", "-t", "tmpfs", "tmpfs", JOURNAL], check=True)

    @classmethod
    def tearDownClass(cls):
        subprocess.run(["umount", JOURNAL], check=True)

    def run_tilth(self, directory, *args, journal_stream=True):
        receiver = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
        receiver.bind(os.path.join(JOURNAL, "socket"))
        receiver.setblocking(False)
        try:
            with open(os.path.join(directory, "stderr.txt"), "w+") as stderr:
                info = os.fstat(stderr.fileno())
                env = dict(os.environ)
                if journal_stream:
                    env["JOURNAL_STREAM"] = f"{info.st_dev}:{info.st_ino}"
                result = subprocess.run([TILTH, "run", DEMO, *args], stdout=subprocess.DEVNULL,
                                        stderr=stderr, env=env, timeout=120)
                stderr.seek(0)
                text = stderr.read()
            entries = []
            while True:
                try:
                    entries.append(parse_entry(receiver.recv(65536)))
                except BlockingIOError:
                    break
        finally:
            receiver.close()
            os.unlink(os.path.join(JOURNAL, "socket"))
        self.assertEqual(result.returncode, 0, text)
        return entries, text

    def test_levels_and_nodes_are_fields(self):
        with tempfile.TemporaryDirectory() as directory:
            # A region of interest reaching out of the image: chain/estimate warns.
            entries, stderr = self.run_tilth(
                directory, "--frames", "2", "--var", 'roi={"x":600,"y":0,"width":100,"height":100}')
        warnings = [e for e in entries if e.get("TILTH_NODE") == "chain/estimate"]
        self.assertTrue(warnings, entries)
        self.assertEqual(warnings[0]["PRIORITY"], "4")  # LOG_WARNING
        self.assertIn("reaches outside the 640x480 image", warnings[0]["MESSAGE"])
        running = [e for e in entries if e.get("TILTH_NODE") == "run"]
        self.assertEqual(running[0]["PRIORITY"], "6")  # LOG_INFO
        self.assertIn("running " + DEMO, running[0]["MESSAGE"])
        # The log lines went to the journal, not to standard error as well.
        self.assertNotIn("reaches outside", stderr)

    def test_without_the_journal_stream_lines_stay_on_stderr(self):
        with tempfile.TemporaryDirectory() as directory:
            entries, stderr = self.run_tilth(directory, "--frames", "2", journal_stream=False)
        self.assertEqual(entries, [])
        self.assertIn("info: run: running " + DEMO, stderr)


if __name__ == "__main__":
    if os.environ.get("TILTH_JOURNAL_TEST_NAMESPACE") != "1":
        unshare = ["unshare", "--mount", "--propagation", "private"]
        probe = subprocess.run(unshare + ["true"], capture_output=True, text=True)
        if probe.returncode != 0:
            print("skipped: no private mount namespace here: " + probe.stderr.strip())
            sys.exit(77)
        os.environ["TILTH_JOURNAL_TEST_NAMESPACE"] = "1"
        os.execvp(unshare[0], unshare + [sys.executable] + sys.argv)
    unittest.main()

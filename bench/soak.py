#!/usr/bin/env python3
"""Soak: `tilth run` serving Modbus for a long time while its cameras drop out and its
PLC reconnects; samples the process's resident memory and open file descriptors, and
says whether they stay flat.

    python3 bench/soak.py --minutes 60 --out soak.csv      (as root: it adds loopback
                                                            addresses for the cameras)

What runs: two Aravis GigE Vision camera simulators (arv-fake-gv-camera-0.8) on
127.0.0.31 / .32 feed graphs/fake-cameras.json (the whole measurement chain), whose
distance goes to a Modbus TCP server on a free port and to a CSV that rotates every
5 MB. Every `--drop-every` seconds the ToF camera's simulator is killed for
`--drop-for` seconds and started again. A PLC (pymodbus) polls every 20 ms and drops its
connection and reconnects every `--reconnect-every` seconds; every poll must get an
answer. Every `--sample-every` seconds a row goes to the CSV: elapsed s, RSS kB, open
fds, threads, polls, poll failures, camera drops.

At the end it prints the figures and the verdict: after the first `--warmup` minutes
(buffers and pools grow to their working size), RSS may grow by at most `--max-rss-growth-kb`
and the number of open fds must not grow at all. Exit code 0 when flat, 1 when not, 2
when something failed to start. Every process it starts is stopped by its pid; tilth's
log is bounded (`--max-log-bytes`).
"""
import argparse
import csv
import json
import os
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time

SOURCE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(SOURCE, "tests", "modbus"))
sys.path.insert(0, os.path.join(SOURCE, "tests", "support"))
from fake_gige_camera import FakeCamera  # noqa: E402
from pymodbus_tcp import ModbusTcpClient  # noqa: E402

def free_port():
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def proc_figures(pid):
    rss_kb = threads = 0
    with open("/proc/%d/status" % pid) as status:
        for line in status:
            if line.startswith("VmRSS:"):
                rss_kb = int(line.split()[1])
            elif line.startswith("Threads:"):
                threads = int(line.split()[1])
    return rss_kb, len(os.listdir("/proc/%d/fd" % pid)), threads


class Plc(threading.Thread):
    """Polls the register block every 20 ms; reconnects every `reconnect_every` s."""

    def __init__(self, port, reconnect_every):
        super().__init__(daemon=True)
        self.port, self.reconnect_every = port, reconnect_every
        self.polls = self.failures = self.reconnects = 0
        self.stopping = threading.Event()

    def run(self):
        while not self.stopping.is_set():
            client = ModbusTcpClient("127.0.0.1", port=self.port, timeout=1)
            client.connect()
            connected_at = time.monotonic()
            while (not self.stopping.is_set()
                   and time.monotonic() - connected_at < self.reconnect_every):
                try:
                    answer = client.read_holding_registers(0, 12, slave=1)
                    self.polls += 1
                    if answer.isError():
                        self.failures += 1
                except Exception:  # noqa: BLE001 -- a failed poll is counted, not fatal
                    self.failures += 1
                    time.sleep(0.2)
                time.sleep(0.02)
            client.close()
            self.reconnects += 1


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--minutes", type=float, default=60.0)
    parser.add_argument("--out", default="soak.csv")
    parser.add_argument("--tilth", default=os.path.join(SOURCE, "build", "bin", "tilth"))
    parser.add_argument("--drop-every", type=float, default=60.0)
    parser.add_argument("--drop-for", type=float, default=3.0)
    parser.add_argument("--reconnect-every", type=float, default=30.0)
    parser.add_argument("--sample-every", type=float, default=10.0)
    parser.add_argument("--warmup", type=float, default=5.0, help="minutes")
    parser.add_argument("--max-rss-growth-kb", type=int, default=8192)
    parser.add_argument("--max-log-bytes", type=int, default=20_000_000)
    args = parser.parse_args()

    depth = FakeCamera("127.0.0.31", "SOAK31")
    color = FakeCamera("127.0.0.32", "SOAK32")
    work = tempfile.mkdtemp(prefix="tilth-soak-")
    port = free_port()
    graph = os.path.join(work, "soak.json")
    with open(graph, "w") as f:
        json.dump({
            "description": "graphs/fake-cameras.json serving Modbus, for bench/soak.py",
            "include": [os.path.join(SOURCE, "graphs", "fake-cameras.json")],
            "nodes": {
                "print": None,
                "log": {"params": {"path": os.path.join(work, "soak.csv"),
                                   "rotate_bytes": 5_000_000}},
                "plc": {"type": "modbus.output",
                        "params": {"port": port, "address": "127.0.0.1"}},
            },
            "edges": [["chain/estimate.distance", "plc.distance"],
                      ["cameras/pair.cameras", "plc.cameras"]],
        }, f)
    log_path = os.path.join(work, "tilth.log")
    tilth = None
    plc = None
    drops = 0
    try:
        depth.start()
        color.start()
        with open(log_path, "w") as log:
            tilth = subprocess.Popen(
                [args.tilth, "run", graph, "--quiet",
                 "--var", "depth_camera=" + depth.address,
                 "--var", "color_camera=" + color.address],
                stdout=log, stderr=log)
        deadline = time.monotonic() + 60
        while True:
            try:
                socket.create_connection(("127.0.0.1", port), timeout=0.2).close()
                break
            except OSError:
                if tilth.poll() is not None or time.monotonic() > deadline:
                    print("soak: tilth did not start serving; its log:", file=sys.stderr)
                    print(open(log_path).read()[-4000:], file=sys.stderr)
                    return 2
                time.sleep(0.1)
        plc = Plc(port, args.reconnect_every)
        plc.start()
        start = time.monotonic()
        next_drop = start + args.drop_every
        next_sample = start
        samples = []
        with open(args.out, "w", newline="") as out:
            writer = csv.writer(out)
            writer.writerow(["elapsed_s", "rss_kb", "fds", "threads", "polls", "poll_failures",
                             "plc_reconnects", "camera_drops"])
            while time.monotonic() - start < args.minutes * 60:
                if tilth.poll() is not None:
                    print("soak: tilth exited with %d" % tilth.returncode, file=sys.stderr)
                    return 1
                if os.path.getsize(log_path) > args.max_log_bytes:
                    print("soak: tilth's log passed %d bytes" % args.max_log_bytes,
                          file=sys.stderr)
                    return 1
                now = time.monotonic()
                if now >= next_drop:
                    depth.kill()
                    time.sleep(args.drop_for)
                    depth.start()
                    drops += 1
                    next_drop = now + args.drop_every
                if now >= next_sample:
                    rss, fds, threads = proc_figures(tilth.pid)
                    row = [round(now - start), rss, fds, threads, plc.polls, plc.failures,
                           plc.reconnects, drops]
                    writer.writerow(row)
                    out.flush()
                    samples.append(row)
                    next_sample = now + args.sample_every
                time.sleep(0.1)
        settled = [row for row in samples if row[0] >= args.warmup * 60] or samples
        rss_growth = settled[-1][1] - settled[0][1]
        fd_growth = settled[-1][2] - settled[0][2]
        print("soak: %.0f min, %d camera drops, %d PLC polls (%d failed), %d reconnects" %
              (args.minutes, drops, plc.polls, plc.failures, plc.reconnects))
        print("soak: RSS %d kB at %d s -> %d kB at the end (max %d kB); fds %d -> %d; "
              "threads %d -> %d" % (settled[0][1], settled[0][0], settled[-1][1],
                                   max(row[1] for row in samples), settled[0][2],
                                   settled[-1][2], settled[0][3], settled[-1][3]))
        flat = rss_growth <= args.max_rss_growth_kb and fd_growth <= 0
        print("soak: %s (RSS growth %d kB, limit %d; fd growth %d, limit 0)" %
              ("flat" if flat else "NOT FLAT", rss_growth, args.max_rss_growth_kb, fd_growth))
        return 0 if flat else 1
    finally:
        if plc is not None:
            plc.stopping.set()
            plc.join(timeout=5)
        if tilth is not None and tilth.poll() is None:
            tilth.send_signal(signal.SIGTERM)
            try:
                tilth.wait(timeout=20)
            except subprocess.TimeoutExpired:
                tilth.kill()
                tilth.wait()
        depth.kill()
        color.kill()


if __name__ == "__main__":
    sys.exit(main())

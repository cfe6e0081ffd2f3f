#!/usr/bin/env python3
"""What the live view (view.live) costs: the CPU time of its threads, and of its stage on
the graph's threads, while nobody watches and while one viewer does.

    python3 bench/live_view_cpu.py [--seconds 20]        (as root: it adds loopback
                                                          addresses for the cameras)

What runs: two Aravis GigE Vision camera simulators at 30 frames/s (640x480 Mono16 depth,
1280x1024 BayerRG8 colour) feed graphs/fake-cameras.json with a view.live node added,
showing every input the machine graphs give it. For `--seconds` without a viewer, then
for as long with one (a client that does what the page does: it holds the event stream
open and pulls each next image as soon as it has the last), it samples the utime+stime of
the process's threads named view-* (/proc/PID/task/*/stat) and the view stage's mean time
per frame (status.json). It prints each as a percentage of one core, with the camera
frames lost, late or incomplete and the graph's drops in each phase. Every process it
starts is stopped by its pid; tilth's log is bounded."""
import argparse
import json
import os
import shutil
import sys
import tempfile
import threading
import time
import urllib.request

SOURCE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(SOURCE, "tests", "support"))
from fake_gige_camera import FakeCamera  # noqa: E402
from ports import free_port  # noqa: E402
from processes import interrupt, start_logged  # noqa: E402

TICKS = os.sysconf("SC_CLK_TCK")


def view_thread_seconds(pid):
    total = 0
    for tid in os.listdir("/proc/%d/task" % pid):
        try:
            with open("/proc/%d/task/%s/stat" % (pid, tid)) as f:
                stat = f.read()
        except OSError:
            continue  # the thread ended
        name = stat[stat.index("(") + 1:stat.rindex(")")]
        fields = stat[stat.rindex(")") + 2:].split()
        if name.startswith("view-"):
            total += int(fields[11]) + int(fields[12])  # utime, stime
    return total / TICKS


class Viewer(threading.Thread):
    """Does what the page does: events held open, each next image pulled at once."""

    def __init__(self, url):
        super().__init__(daemon=True)
        self.url, self.images, self.bytes = url, 0, 0
        self.stopping = threading.Event()

    def run(self):
        events = urllib.request.urlopen(self.url + "events", timeout=10)
        def drain():
            try:
                while events.read1(65536):
                    pass
            except (OSError, ValueError, AttributeError):
                pass  # closed at the end
        threading.Thread(target=drain, daemon=True).start()
        generation = 0
        while not self.stopping.is_set():
            with urllib.request.urlopen(self.url + "frame.jpg?after=%d" % generation,
                                        timeout=10) as reply:
                if reply.status == 200:
                    generation = int(reply.headers["X-Generation"])
                    self.bytes += len(reply.read())
                    self.images += 1
        events.close()


def measure(tilth, url, seconds):
    def view_stage():
        status = json.loads(urllib.request.urlopen(url + "status.json", timeout=10).read())
        stage = next(s for s in status["stages"] if s["node"] == "view")
        return status, stage
    status0, _ = view_stage()
    cpu0, wall0 = view_thread_seconds(tilth.pid), time.monotonic()
    time.sleep(seconds)
    cpu1, wall1 = view_thread_seconds(tilth.pid), time.monotonic()
    status1, stage = view_stage()
    frames = status1["frames_completed"] - status0["frames_completed"]
    cameras = ("lost", "late", "incomplete")
    missed = sum(status1["cameras"][k] - status0["cameras"][k] for k in cameras)
    wall = wall1 - wall0
    return {"frames_per_second": frames / wall,
            "view_threads_percent": 100.0 * (cpu1 - cpu0) / wall,
            "view_stage_percent": 100.0 * stage["mean_ms"] * 1e-3 * frames / wall,
            "images": status1["images_rendered"] - status0["images_rendered"],
            "camera_frames_missed": missed,
            "graph_frames_dropped": status1["frames_dropped"] - status0["frames_dropped"]}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=20.0)
    parser.add_argument("--tilth", default=os.path.join(SOURCE, "build", "bin", "tilth"))
    args = parser.parse_args()

    depth = FakeCamera("127.0.0.41", "VIEW41")
    color = FakeCamera("127.0.0.42", "VIEW42")
    work = tempfile.mkdtemp(prefix="tilth-view-bench-")
    view_port = free_port()
    graph = os.path.join(work, "view.json")
    with open(graph, "w") as f:
        json.dump({
            "description": "graphs/fake-cameras.json with the live view, for bench/live_view_cpu.py",
            "include": [os.path.join(SOURCE, "graphs", "fake-cameras.json")],
            "nodes": {
                "print": None,
                "log": {"params": {"path": os.path.join(work, "view.csv")}},
                "view": {"type": "view.live", "params": {"listen": "127.0.0.1:%d" % view_port}},
            },
            "edges": [["chain/estimate.distance", "view.distance"],
                      ["cameras/pair.color", "view.color"],
                      ["chain/register.color", "view.registered"],
                      ["chain/segment.mask", "view.mask"],
                      ["chain/project.depth", "view.depth"],
                      ["cameras/pair.cameras", "view.cameras"]],
        }, f)
    url = "http://127.0.0.1:%d/" % view_port
    log_path = os.path.join(work, "tilth.log")
    tilth = None
    try:
        depth.start()
        color.start()
        tilth = start_logged([args.tilth, "run", graph, "--quiet",
                              "--var", "depth_camera=" + depth.address,
                              "--var", "color_camera=" + color.address], log_path)
        deadline = time.monotonic() + 60
        while True:
            try:
                status = json.loads(urllib.request.urlopen(url + "status.json", timeout=2).read())
                if status["frames_completed"] > 30:
                    break
            except OSError:
                pass
            if tilth.poll() is not None or time.monotonic() > deadline:
                print("tilth did not start streaming; its log:", open(log_path).read()[-3000:])
                return 2
            time.sleep(0.2)
        idle = measure(tilth, url, args.seconds)
        viewer = Viewer(url)
        viewer.start()
        time.sleep(2.0)
        watched = measure(tilth, url, args.seconds)
        viewer.stopping.set()
        viewer.join(15)
        for name, figures in (("nobody watching", idle), ("one viewer", watched)):
            print("%-16s %5.1f frames/s  view threads %5.2f %% of a core  view stage %5.3f %%  "
                  "images drawn %d  camera frames lost/late/incomplete %d  graph drops %d" % (
                      name, figures["frames_per_second"], figures["view_threads_percent"],
                      figures["view_stage_percent"], figures["images"],
                      figures["camera_frames_missed"], figures["graph_frames_dropped"]))
        if viewer.images:
            print("image size %.0f kB mean (%d images pulled)" %
                  (viewer.bytes / viewer.images / 1000, viewer.images))
        return 0
    finally:
        interrupt(tilth)
        depth.kill()
        color.kill()
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())

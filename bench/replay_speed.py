#!/usr/bin/env python3
"""How fast one recording replays through the measurement chain: graphs/paper.json over
an image-folder recording (PNG files, decoded `decode_ahead` frames ahead of the graph)
and over the same frames as an MCAP recording (mcap.player), in frames per second.

    python3 bench/replay_speed.py [--frames 60] [--preset case_e] [--runs 3]

The simulator renders the frames once (1280x1024 colour, 640x480 depth); each replay is
`tilth run` to a CSV, timed from start to exit (start-up included: about 0.3 s), the
fastest of --runs. It prints frames/s per replay and per core used."""
import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

SOURCE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def timed_run(tilth, graph, sets, runs):
    best = None
    for _ in range(runs):
        start = time.monotonic()
        done = subprocess.run([tilth, "run", graph, "--quiet"] + sum([["--set", s] for s in sets], []),
                              stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                              timeout=600)
        seconds = time.monotonic() - start
        if done.returncode != 0:
            raise RuntimeError("tilth run failed: " + done.stderr[-2000:])
        best = seconds if best is None else min(best, seconds)
    return best


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--frames", type=int, default=60)
    parser.add_argument("--preset", default="case_e")
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--tilth", default=os.path.join(SOURCE, "build", "bin", "tilth"))
    args = parser.parse_args()
    work = tempfile.mkdtemp(prefix="tilth-replay-bench-")
    try:
        folder = os.path.join(work, "rec")
        mcap = os.path.join(work, "rec.mcap")
        for output in (folder, mcap):
            subprocess.run([args.tilth, "simulate", output, "--preset", args.preset, "--frames",
                            str(args.frames)], check=True, stdout=subprocess.DEVNULL)
        paper = os.path.join(SOURCE, "graphs", "paper.json")
        mcap_graph = os.path.join(work, "mcap.json")
        with open(mcap_graph, "w") as f:
            json.dump({"description": "graphs/paper.json from an MCAP recording",
                       "include": [paper],
                       "nodes": {"input": None,
                                 "player": {"type": "mcap.player", "params": {"path": mcap}}},
                       "edges": [["player.raw", "chain/project.raw"],
                                 ["player.color", "chain/register.color"],
                                 ["player.truth", "output.truth"]]}, f)
        out = "output.path=" + os.path.join(work, "out.csv")
        cores = os.cpu_count()
        replays = [("image folder, decode_ahead %d" % n, paper,
                    ["input.path=" + folder, "input.decode_ahead=%d" % n, out], n)
                   for n in sorted({1, cores})]
        replays.append(("MCAP", mcap_graph, [out], 1))
        for name, graph, sets, _ in replays:
            seconds = timed_run(args.tilth, graph, sets, args.runs)
            print("%-30s %6.2f s  %6.1f frames/s  %5.1f frames/s per core (%d cores)" %
                  (name, seconds, args.frames / seconds, args.frames / seconds / cores, cores))
        return 0
    finally:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())

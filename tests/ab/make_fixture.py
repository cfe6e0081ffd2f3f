"""Makes what the tilth ab tests read, in $AB_FIXTURE. Recordings (in recordings/) of
the simulator's case C at half the paper rig's resolution, so that they take seconds:
  case_c         3 frames as simulated (image folder)
  case_c_hidden  the same with edited truth: frame 1's mask all residue (no visible
                 soil), frame 2 without truth distance or mask (image folder)
  case_c_mcap    case_c converted to an MCAP file
then `tilth ab` run twice on them with three variants (once keeping every image, once
one graph at a time), and graphs/paper.json on case_c for a cross-check. Tags: case_c's
recording.json says site north and light sun (case_c_hidden copies it), tags.csv moves
case_c_hidden to site south; the MCAP file has none."""
import csv
import json
import os
import shutil
import subprocess
import sys

import cv2
import numpy as np

TILTH = os.environ["TILTH_BIN"]
SOURCE = os.environ["TILTH_SOURCE_DIR"]
FIXTURE = os.environ["AB_FIXTURE"]
CALIBRATION = os.path.join(os.path.dirname(os.path.abspath(__file__)), "half_rig.calib.json")
RECORDINGS = os.path.join(FIXTURE, "recordings")


def run(command):
    print("+", " ".join(command), flush=True)
    result = subprocess.run(command, capture_output=True, text=True, timeout=150)
    if result.returncode != 0:
        sys.exit("failed (%d): %s\n%s%s" % (result.returncode, " ".join(command), result.stdout,
                                              result.stderr))
    return result


def simulate(preset, frames, folder):
    run([TILTH, "run", os.path.join(SOURCE, "graphs", "simulate.json"), "--quiet",
         "--var", "calibration=" + CALIBRATION, "--set", "scene.preset=" + preset,
         "--set", "scene.frames=%d" % frames, "--set", "recording.path=" + folder])


def hide_truth(folder, copy):
    """Frame 1: no soil in the truth mask; frame 2: no truth at all."""
    shutil.copytree(folder, copy)
    frames_csv = os.path.join(copy, "frames.csv")
    with open(frames_csv) as f:
        rows = list(csv.DictReader(f))
    fields = list(rows[0].keys())
    mask_file = os.path.join(copy, rows[1]["mask"])
    mask = cv2.imread(mask_file, cv2.IMREAD_UNCHANGED)
    cv2.imwrite(mask_file, np.full_like(mask, 255))
    os.remove(os.path.join(copy, rows[2]["mask"]))
    rows[2]["mask"] = ""
    rows[2]["ground_truth_mm"] = ""
    with open(frames_csv, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=fields, lineterminator="\n")
        writer.writeheader()
        writer.writerows(rows)


def convert_to_mcap(folder, mcap):
    graph = os.path.join(FIXTURE, "to-mcap.json")
    with open(graph, "w") as f:
        json.dump({
            "nodes": {
                "replay": {"type": "recording.image_folder",
                           "params": {"path": folder, "host_time": "recorded"}},
                "record": {"type": "mcap.writer",
                           "params": {"path": mcap, "calibration": CALIBRATION}}},
            "edges": [["replay.raw", "record.raw"], ["replay.color", "record.color"],
                      ["replay.truth", "record.truth"]]}, f)
    run([TILTH, "run", graph, "--quiet"])


VARIANTS = os.path.join(FIXTURE, "variants.json")
TAGS = os.path.join(FIXTURE, "tags.csv")
BASELINE = "wide"


def tag(folder, tags):
    path = os.path.join(folder, "recording.json")
    with open(path) as f:
        recording = json.load(f)
    recording["tags"] = tags
    with open(path, "w") as f:
        json.dump(recording, f, indent=2)


def comparison(out):
    """The command line of the fixture's comparison of three variants on the recordings
    (test_shards.py runs it as shards)."""
    return [TILTH, "ab", RECORDINGS, "--variants", VARIANTS,
            "--variant", "wide:segment.dilation_px=5",
            "--variant", "plane:estimate.type=estimation.ground_plane",
            "--variant", "plane:estimate.calibration=" + CALIBRATION,
            "--var", "calibration=" + CALIBRATION, "--baseline", BASELINE, "--tags", TAGS,
            "--overlays", "2", "--out", out, "--quiet"]


def compare(out, *extra):
    with open(VARIANTS, "w") as f:
        json.dump({"variants": [{"name": "threshold",
                                 "description": "the paper's colour threshold, as in the chain"}]},
                  f)
    return run(comparison(out) + list(extra))


def main():
    shutil.rmtree(FIXTURE, ignore_errors=True)
    os.makedirs(RECORDINGS)
    case_c = os.path.join(RECORDINGS, "case_c")
    simulate("case_c", 3, case_c)
    tag(case_c, {"site": "north", "light": "sun"})
    with open(TAGS, "w") as f:
        f.write("recording,site\ncase_c_hidden,south\n")
    hide_truth(case_c, os.path.join(RECORDINGS, "case_c_hidden"))
    convert_to_mcap(case_c, os.path.join(RECORDINGS, "case_c_mcap.mcap"))
    compare(os.path.join(FIXTURE, "report"), "--keep-images")
    compare(os.path.join(FIXTURE, "report-serial"), "--jobs", "1")
    run([TILTH, "run", os.path.join(SOURCE, "graphs", "paper.json"), "--quiet",
         "--var", "calibration=" + CALIBRATION, "--set", "input.path=" + case_c,
         "--set", "output.path=" + os.path.join(FIXTURE, "paper-case_c.csv")])


if __name__ == "__main__":
    main()

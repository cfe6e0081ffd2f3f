"""A simulated recording through `tilth ab`: the chain's variants compared on a scene of
the simulator, for tests that pin what a variant does on one kind of field."""
import json
import os
import subprocess


def simulate(tilth, folder, preset, *options):
    """`tilth simulate FOLDER --preset PRESET OPTIONS...`; returns the folder."""
    result = subprocess.run([tilth, "simulate", folder, "--preset", preset, *options],
                            capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr[-2000:]
    return folder


def compare(tilth, recording, report, *variants):
    """`tilth ab RECORDING` with each `--variant` of `variants` into `report`."""
    command = [tilth, "ab", recording, "--out", report, "--overlays", "0", "--quiet"]
    for variant in variants:
        command += ["--variant", variant]
    result = subprocess.run(command, capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr[-2000:]
    return report


def frames_of(report, variant, recording):
    """The frames (frames.jsonl) of `variant` on `recording` in a `tilth ab` report."""
    with open(os.path.join(report, "runs", variant, recording, "frames.jsonl")) as f:
        return [json.loads(line) for line in f]

"""What the tests of shards and of the fleet's job files (deploy/fleet/) share: the
fixture's comparison (make_fixture.py) as the job files' environment variables, and the
comparison of a merged report with the fixture's single run."""
import csv
import json
import os

from make_fixture import FIXTURE, SOURCE, TILTH, comparison

FLEET = os.path.join(SOURCE, "deploy", "fleet")
SLURM = os.path.join(FLEET, "slurm")
KUBERNETES = os.path.join(FLEET, "kubernetes")
SINGLE_RUN = os.path.join(FIXTURE, "report")
# What differs from run to run: when and how the report was made, stage times, frame rates.
UNSTABLE = ("made", "stage_times", "frames_per_second")


def fleet_environment(out, shards):
    """The job files' variables for the fixture's comparison in `shards` shards into `out`."""
    command = comparison(out)
    assert command[:2] == [TILTH, "ab"] and command[3] == "--variants", command
    rest = command[5:]
    at = rest.index("--out")
    del rest[at:at + 2]
    assert not any(" " in word for word in rest), rest
    return {"TILTH": TILTH, "TILTH_AB_RECORDINGS": command[2], "TILTH_AB_VARIANTS": command[4],
            "TILTH_AB_OUT": out, "TILTH_AB_SHARDS": str(shards),
            "TILTH_AB_OPTIONS": " ".join(rest)}


def stable(value):
    if isinstance(value, dict):
        return {k: stable(v) for k, v in value.items() if k not in UNSTABLE}
    if isinstance(value, list):
        return [stable(v) for v in value]
    return value


def summary(folder):
    with open(os.path.join(folder, "summary.json")) as f:
        return stable(json.load(f))


def summary_rows(folder):
    """summary.csv without its timing columns (ms_per_frame, chain_ms_per_frame, ...)."""
    with open(os.path.join(folder, "summary.csv")) as f:
        return [{k: v for k, v in row.items() if not k.endswith("ms_per_frame")}
                for row in csv.DictReader(f)]


def read(path):
    with open(path) as f:
        return f.read()


def assert_same_as_single_run(test, merged):
    """The report in `merged` is the fixture's single run's, apart from timings."""
    test.assertEqual(summary(merged), summary(SINGLE_RUN))
    test.assertEqual(summary_rows(merged), summary_rows(SINGLE_RUN))
    for name in ("frames.csv", "conditions.csv"):
        test.assertEqual(read(os.path.join(merged, name)), read(os.path.join(SINGLE_RUN, name)),
                         name)
    test.assertTrue(os.path.getsize(os.path.join(merged, "report.html")) > 10000)

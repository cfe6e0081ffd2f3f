"""`tilth ab --shard I/N` and `tilth ab merge`: the fixture's comparison (make_fixture.py)
run as three shards, in two folders, merges into the report the single run wrote, apart
from timings; a shard that did not finish is listed, not dropped; running a shard again
replaces its results only; shards of different comparisons are refused."""
import json
import os
import shutil
import subprocess
import tempfile
import unittest

from fleet_support import assert_same_as_single_run
from make_fixture import TILTH, comparison

SHARDS = 3
# Variants x recordings of the fixture's comparison, variant-major as the jobs are.
VARIANTS = ["threshold", "wide", "plane"]
RECORDINGS = ["case_c", "case_c_hidden", "case_c_mcap"]


def run(command):
    return subprocess.run(command, capture_output=True, text=True, timeout=150)


def shard(index, out, *extra):
    command = comparison(out) + ["--shard", "%d/%d" % (index, SHARDS), *extra]
    result = run(command)
    assert result.returncode == 0, result.stderr
    return result


def merge(*folders_and_options):
    return run([TILTH, "ab", "merge", *folders_and_options])


def summary(folder):
    with open(os.path.join(folder, "summary.json")) as f:
        return json.load(f)


def job_labels(index):
    """The variant@recording of the jobs of shard `index`."""
    jobs = [v + "@" + r for v in VARIANTS for r in RECORDINGS]
    return [label for j, label in enumerate(jobs) if j % SHARDS == index]


class ShardsTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.folder = tempfile.mkdtemp(prefix="tilth-ab-shards-")
        cls.shared = os.path.join(cls.folder, "shared")  # shards 0 and 1
        cls.other = os.path.join(cls.folder, "other")  # shard 2, as from another machine
        shard(0, cls.shared)
        shard(1, cls.shared)
        shard(2, cls.other)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.folder)

    def out(self, name):
        return os.path.join(self.folder, name)

    def assert_same_report(self, merged):
        assert_same_as_single_run(self, merged)

    def test_merged_shards_give_the_single_runs_report(self):
        result = merge(self.shared, self.other, "--out", self.out("merged"), "--quiet")
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assert_same_report(self.out("merged"))
        merged = summary(self.out("merged"))
        self.assertEqual(len(merged["recording_figures"]), len(VARIANTS) * len(RECORDINGS))
        # The overlays read the masks each shard saved: two frames of each recording.
        self.assertEqual([len(d["frames"]) for d in merged["disagreements"]], [2, 2, 2])
        self.assertTrue(os.path.getsize(os.path.join(self.out("merged"), "report.html")) > 100000)
        # Stamped with the merge's command line and each shard's.
        made = merged["made"]
        self.assertEqual(made["command_line"][:3], ["tilth", "ab", "merge"])
        self.assertEqual(sorted(line[line.index("--shard") + 1] for line in made["shard_command_lines"]),
                         ["0/3", "1/3", "2/3"])

    def test_a_shard_that_did_not_finish_is_listed_and_fails_the_merge(self):
        result = merge(self.shared, "--out", self.out("partial"), "--quiet")
        self.assertEqual(result.returncode, 1, result.stderr)
        missing = job_labels(2)
        self.assertIn("%d of 9 jobs missing" % len(missing), result.stderr)
        for label in missing:
            self.assertIn("shard 2/3: " + label, result.stderr)
        rows = {r["variant"] + "@" + r["recording"]: r
                for r in summary(self.out("partial"))["recording_figures"]}
        self.assertEqual(len(rows), 9)
        for label, row in rows.items():
            with self.subTest(job=label):
                if label in missing:
                    self.assertTrue(row["failed"])
                    self.assertEqual(row["failure"], "missing: shard 2/3 left no result of this job")
                    self.assertEqual(row["figures"]["frames"], 0)
                else:
                    self.assertFalse(row["failed"])
                    self.assertEqual(row["figures"]["frames"], 3)

    def test_running_a_shard_again_replaces_only_its_results(self):
        folder = self.out("rerun")
        shutil.copytree(self.shared, folder)

        def records(index):
            result = {}
            for label in job_labels(index):
                variant, recording = label.split("@")
                path = os.path.join(folder, "runs", variant, recording, "job.json")
                result[label] = (os.stat(path).st_mtime_ns, open(path).read())
            return result

        before = {index: records(index) for index in (0, 1)}
        shard(1, folder)
        self.assertEqual(records(0), before[0])
        for label, (stamp, _) in records(1).items():
            self.assertGreater(stamp, before[1][label][0], label)
        self.assertEqual(sorted(os.listdir(os.path.join(folder, "shards"))),
                         ["0-of-3.json", "1-of-3.json"])
        result = merge(folder, self.other, "--out", self.out("rerun-merged"), "--quiet")
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assert_same_report(self.out("rerun-merged"))

    def test_shards_of_different_comparisons_are_refused(self):
        odd = self.out("odd")
        shard(2, odd, "--no-soil-below", "0.2")
        result = merge(self.shared, odd, "--out", self.out("mixed"))
        self.assertEqual(result.returncode, 1, result.stderr)
        self.assertIn("ran different comparisons", result.stderr)
        self.assertIn(os.path.join(odd, "shards", "2-of-3.json"), result.stderr)
        self.assertFalse(os.path.exists(self.out("mixed")))

    def test_shard_and_merge_mistakes(self):
        for bad in ("3/3", "1", "a/2", "0/0", "-1/2", "1/2/3"):
            with self.subTest(shard=bad):
                result = run(comparison(self.out("bad")) + ["--shard", bad])
                self.assertEqual(result.returncode, 2, result.stderr)
                self.assertIn("--shard " + bad + ": expected I/N", result.stderr)
        not_shards = self.out("not-shards")
        os.makedirs(not_shards)
        open(os.path.join(not_shards, "notes.txt"), "w").close()
        result = run(comparison(not_shards) + ["--shard", "0/3"])
        self.assertEqual(result.returncode, 2, result.stderr)
        self.assertIn("holds no shard results", result.stderr)
        for arguments, message in (
                ((self.shared,), "--out DIR is required"),
                (("--out", self.out("x")), "no shard folder given"),
                ((self.out("nowhere"), "--out", self.out("x")), "nowhere: no such folder"),
                ((self.shared, "--out", self.out("x"), "--shards"), "unknown option --shards")):
            with self.subTest(arguments=arguments):
                result = merge(*arguments)
                self.assertEqual(result.returncode, 2, result.stderr)
                self.assertIn(message, result.stderr)
        result = merge(not_shards, "--out", self.out("x"))
        self.assertEqual(result.returncode, 1, result.stderr)
        self.assertIn("no finished shard in the folders given", result.stderr)


if __name__ == "__main__":
    unittest.main()

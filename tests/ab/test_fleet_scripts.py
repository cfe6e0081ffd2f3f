"""The Slurm job files of deploy/fleet/slurm run without Slurm: shard.sbatch once per
array index (SLURM_ARRAY_TASK_ID set as a task of `sbatch --array` has it), then
merge.sbatch, give the fixture's single-run report (make_fixture.py); a shard run again
with the merge again still does; every missing variable or wrong index is named."""
import os
import shutil
import subprocess
import tempfile
import unittest

from fleet_support import SLURM, assert_same_as_single_run, fleet_environment

SHARDS = 3


def run_script(name, environment, folder):
    env = {k: v for k, v in os.environ.items()
           if not k.startswith(("SLURM_", "TILTH_AB_", "JOB_COMPLETION_INDEX"))}
    env.update(environment)
    return subprocess.run(["bash", os.path.join(SLURM, name)], env=env, cwd=folder,
                          capture_output=True, text=True, timeout=150)


def array_task(index, count):
    """What Slurm sets in each task of `sbatch --array=0-(count-1)`."""
    return {"SLURM_ARRAY_TASK_ID": str(index), "SLURM_ARRAY_TASK_COUNT": str(count),
            "SLURM_ARRAY_TASK_MIN": "0", "SLURM_ARRAY_TASK_MAX": str(count - 1),
            "SLURM_CPUS_PER_TASK": "2"}


class SlurmScriptsTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.folder = tempfile.mkdtemp(prefix="tilth-fleet-scripts-")

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.folder)

    def test_array_then_merge_gives_the_single_run(self):
        out = os.path.join(self.folder, "array")
        env = fleet_environment(out, SHARDS)
        # Shard 0 takes N from TILTH_AB_SHARDS, the others from the array's own size.
        for index in range(SHARDS):
            task = dict(env, **array_task(index, SHARDS))
            if index > 0:
                del task["TILTH_AB_SHARDS"]
            result = run_script("shard.sbatch", task, self.folder)
            self.assertEqual(result.returncode, 0, result.stderr)
            self.assertIn("shard %d/%d" % (index, SHARDS), result.stdout)
            self.assertTrue(os.path.isfile(os.path.join(
                out, "shard-%d" % index, "shards", "%d-of-%d.json" % (index, SHARDS))))
        self.assertEqual(sorted(os.listdir(out)), ["shard-%d" % i for i in range(SHARDS)])
        result = run_script("merge.sbatch", {"TILTH": env["TILTH"], "TILTH_AB_OUT": out},
                            self.folder)
        self.assertEqual(result.returncode, 0, result.stderr)
        assert_same_as_single_run(self, os.path.join(out, "report"))

        # Shard 1 again, as `sbatch --array=1` with TILTH_AB_SHARDS, then the merge again
        # over the earlier report.
        task = dict(env, **array_task(1, 1))
        task["SLURM_ARRAY_TASK_MIN"] = task["SLURM_ARRAY_TASK_MAX"] = "1"
        result = run_script("shard.sbatch", task, self.folder)
        self.assertEqual(result.returncode, 0, result.stderr)
        report = os.path.join(self.folder, "elsewhere")
        for _ in range(2):
            result = run_script("merge.sbatch", {"TILTH": env["TILTH"], "TILTH_AB_OUT": out,
                                                 "TILTH_AB_REPORT": report}, self.folder)
            self.assertEqual(result.returncode, 0, result.stderr)
            assert_same_as_single_run(self, report)

    def test_a_missing_shard_fails_the_merge(self):
        out = os.path.join(self.folder, "partial")
        env = fleet_environment(out, SHARDS)
        for index in (0, 2):
            result = run_script("shard.sbatch", dict(env, **array_task(index, SHARDS)),
                                self.folder)
            self.assertEqual(result.returncode, 0, result.stderr)
        result = run_script("merge.sbatch", {"TILTH": env["TILTH"], "TILTH_AB_OUT": out},
                            self.folder)
        self.assertEqual(result.returncode, 1, result.stderr)
        self.assertIn("jobs missing", result.stderr)
        self.assertIn("shard 1/3: ", result.stderr)

    def test_mistakes_are_named(self):
        out = os.path.join(self.folder, "mistakes")
        env = fleet_environment(out, SHARDS)
        cases = [
            ({k: v for k, v in env.items()}, "SLURM_ARRAY_TASK_ID is not set"),
            (dict(env, TILTH_AB_RECORDINGS="", **array_task(0, 3)), "TILTH_AB_RECORDINGS is not set"),
            (dict(env, TILTH_AB_VARIANTS="", **array_task(0, 3)), "TILTH_AB_VARIANTS is not set"),
            (dict(env, TILTH_AB_OUT="", **array_task(0, 3)), "TILTH_AB_OUT is not set"),
            (dict(env, **array_task(3, 4)), "shard index 3 is not below the shard count 3"),
            (dict(env, **array_task(0, 3), TILTH_AB_SHARDS="x"),
             "shard index '0' and count 'x' must be numbers"),
        ]
        rerun = dict(env, **array_task(2, 1))
        del rerun["TILTH_AB_SHARDS"]
        rerun["SLURM_ARRAY_TASK_MIN"] = rerun["SLURM_ARRAY_TASK_MAX"] = "2"
        cases.append((rerun, "TILTH_AB_SHARDS is not set and this array is not 0..N-1"))
        for environment, message in cases:
            with self.subTest(message=message):
                result = run_script("shard.sbatch", environment, self.folder)
                self.assertEqual(result.returncode, 2, result.stderr)
                self.assertIn("tilth-ab shard: " + message, result.stderr)
                self.assertIn("usage:", result.stderr)
        self.assertFalse(os.path.exists(out))
        for environment, message in (({}, "TILTH_AB_OUT is not set"),
                                     ({"TILTH_AB_OUT": out}, out + ": no such folder"),
                                     ({"TILTH_AB_OUT": self.folder}, "no shard-* folder")):
            with self.subTest(message=message):
                result = run_script("merge.sbatch", environment, self.folder)
                self.assertEqual(result.returncode, 2, result.stderr)
                self.assertIn("tilth-ab merge: " + message, result.stderr)

    def test_submit_wrapper_checks_its_arguments(self):
        submit = os.path.join(SLURM, "submit.sh")
        env = fleet_environment(os.path.join(self.folder, "submit"), SHARDS)
        recordings, variants = env["TILTH_AB_RECORDINGS"], env["TILTH_AB_VARIANTS"]
        base = ["--variants", variants, "--out", os.path.join(self.folder, "s"), recordings]
        for arguments, message in (
                (base, "--shards N is required"),
                (["--shards", "0"] + base, "--shards N is required"),
                (["--shards", "2", "--parallel", "x"] + base, "--parallel K must be a number"),
                (["--shards", "2", "--out", "o", recordings], "--variants FILE is required"),
                (["--shards", "2", "--variants", variants, recordings], "--out DIR is required"),
                (["--shards", "2", "--variants", variants, "--out", "o"], "no recording given"),
                (["--shards", "2", "--variants", "/nowhere.json", "--out", "o", recordings],
                 "/nowhere.json: no such file"),
                (["--shards", "2", "--merge-after", "maybe"] + base, "--merge-after must be ok or any"),
                (["--shards", "2", "--bogus"] + base, "unknown option --bogus")):
            with self.subTest(arguments=arguments):
                result = subprocess.run(["bash", submit, *arguments], capture_output=True,
                                        text=True, timeout=30, cwd=self.folder)
                self.assertEqual(result.returncode, 2, result.stderr)
                self.assertIn("submit.sh: " + message, result.stderr)
                self.assertIn("usage: submit.sh --shards N", result.stderr)


if __name__ == "__main__":
    unittest.main()

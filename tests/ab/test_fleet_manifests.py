"""The Kubernetes manifests of deploy/fleet/kubernetes, without a cluster, beyond their
schemas (kubernetes/manifest_schemas.test.mjs validates them against the Kubernetes API's
own): each parses (python3-yaml); the kinds and apiVersions; no unknown key where this
test knows the object's fields (the API's schemas allow them, and a misspelt key would be
dropped or refused by the API server); the shards' Job is Indexed with completions
equal to the shard count its pods pass to --shard and parallelism at most completions;
JOB_COMPLETION_INDEX goes to --shard and to the shard's folder; both Jobs mount the
PVC of storage.yaml, ReadWriteMany, at the paths of their variables; the merge reads
where the shards write. Then each Job's container command runs here, as its pods would
(the shards' with JOB_COMPLETION_INDEX 0..N-1, paths of the fixture instead of /data),
and the merged report is the fixture's single run's (make_fixture.py)."""
import os
import shutil
import subprocess
import tempfile
import unittest

import yaml

from fleet_support import KUBERNETES, assert_same_as_single_run, fleet_environment

# The fields of the objects that the manifests use (Kubernetes API reference, v1.30).
KNOWN = {
    "object": {"apiVersion", "kind", "metadata", "spec"},
    "metadata": {"name", "namespace", "labels", "annotations"},
    "job_spec": {"completionMode", "completions", "parallelism", "backoffLimit",
                 "backoffLimitPerIndex", "maxFailedIndexes", "activeDeadlineSeconds",
                 "ttlSecondsAfterFinished", "podFailurePolicy", "suspend", "template",
                 "selector", "manualSelector", "podReplacementPolicy"},
    "pod_template": {"metadata", "spec"},
    "pod_spec": {"restartPolicy", "containers", "initContainers", "volumes",
                 "nodeSelector", "tolerations", "affinity", "securityContext",
                 "serviceAccountName", "imagePullSecrets", "priorityClassName"},
    "container": {"name", "image", "imagePullPolicy", "command", "args", "env", "envFrom",
                  "resources", "volumeMounts", "workingDir", "securityContext"},
    "env": {"name", "value", "valueFrom"},
    "volume_mount": {"name", "mountPath", "readOnly", "subPath"},
    "volume": {"name", "persistentVolumeClaim", "configMap", "emptyDir", "nfs", "hostPath"},
    "resources": {"requests", "limits"},
    "pvc_spec": {"accessModes", "storageClassName", "resources", "volumeName",
                 "volumeMode", "selector"},
}


def load(name):
    with open(os.path.join(KUBERNETES, name)) as f:
        documents = [d for d in yaml.safe_load_all(f) if d is not None]
    assert len(documents) == 1, (name, len(documents))
    return documents[0]


def container(job):
    containers = job["spec"]["template"]["spec"]["containers"]
    assert len(containers) == 1, containers
    return containers[0]


def env_of(job):
    return {e["name"]: e["value"] for e in container(job)["env"]}


class ManifestsTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.storage = load("storage.yaml")
        cls.shards = load("shards-job.yaml")
        cls.merge = load("merge-job.yaml")

    def assert_known(self, value, kind, where):
        self.assertIsInstance(value, dict, where)
        unknown = set(value) - KNOWN[kind]
        self.assertFalse(unknown, "%s: unknown keys %s" % (where, sorted(unknown)))

    def check_job(self, job, name):
        self.assert_known(job, "object", name)
        self.assertEqual((job["apiVersion"], job["kind"]), ("batch/v1", "Job"), name)
        self.assert_known(job["metadata"], "metadata", name + ":/metadata")
        spec = job["spec"]
        self.assert_known(spec, "job_spec", name + ":/spec")
        for key in ("completions", "parallelism", "backoffLimit"):
            self.assertIsInstance(spec[key], int, name + ":/spec/" + key)
            self.assertGreaterEqual(spec[key], 0, key)
        self.assertLessEqual(spec["parallelism"], spec["completions"], name)
        self.assert_known(spec["template"], "pod_template", name + ":/spec/template")
        pod = spec["template"]["spec"]
        self.assert_known(pod, "pod_spec", name + ":/spec/template/spec")
        self.assertIn(pod["restartPolicy"], ("Never", "OnFailure"))  # what a Job allows
        c = container(job)
        self.assert_known(c, "container", name + ": container")
        self.assertIsInstance(c["image"], str)
        self.assertTrue(all(isinstance(word, str) for word in c["command"]), c["command"])
        for e in c["env"]:
            self.assert_known(e, "env", name + ": env")
            self.assertIsInstance(e["value"], str, e)  # env values must be strings
        self.assert_known(c["resources"], "resources", name + ": resources")
        volumes = {v["name"]: v for v in pod["volumes"]}
        for v in pod["volumes"]:
            self.assert_known(v, "volume", name + ": volume")
        for m in c["volumeMounts"]:
            self.assert_known(m, "volume_mount", name + ": volumeMount")
            self.assertIn(m["name"], volumes, name + ": a mount of no volume")
        return volumes, c

    def test_storage_is_a_shared_claim(self):
        self.assert_known(self.storage, "object", "storage.yaml")
        self.assertEqual((self.storage["apiVersion"], self.storage["kind"]),
                         ("v1", "PersistentVolumeClaim"))
        self.assert_known(self.storage["spec"], "pvc_spec", "storage.yaml:/spec")
        self.assertEqual(self.storage["spec"]["accessModes"], ["ReadWriteMany"])
        self.assertIn("storage", self.storage["spec"]["resources"]["requests"])

    def test_shards_are_an_indexed_job_of_n_completions(self):
        self.check_job(self.shards, "shards-job.yaml")
        spec = self.shards["spec"]
        self.assertEqual(spec["completionMode"], "Indexed")
        env = env_of(self.shards)
        self.assertEqual(int(env["TILTH_AB_SHARDS"]), spec["completions"],
                         "TILTH_AB_SHARDS (the N of --shard) differs from completions")
        script = container(self.shards)["command"][-1]
        self.assertIn("${TILTH_AB_INDEX:-$JOB_COMPLETION_INDEX}", script)
        self.assertIn('--shard "$index/$TILTH_AB_SHARDS"', script)
        self.assertIn('--out "$TILTH_AB_OUT/shard-$index"', script)
        self.assertIn("set -euo pipefail", script)

    def test_merge_reads_where_the_shards_write(self):
        self.check_job(self.merge, "merge-job.yaml")
        self.assertNotIn("completionMode", self.merge["spec"])
        self.assertEqual(self.merge["spec"]["completions"], 1)
        self.assertEqual(env_of(self.merge)["TILTH_AB_OUT"], env_of(self.shards)["TILTH_AB_OUT"])
        self.assertEqual(container(self.merge)["image"], container(self.shards)["image"])
        script = container(self.merge)["command"][-1]
        self.assertIn('"$TILTH_AB_OUT"/shard-*', script)
        self.assertIn('--out "$TILTH_AB_REPORT"', script)

    def test_both_jobs_mount_the_claim_where_their_paths_are(self):
        claim = self.storage["metadata"]["name"]
        for job, name in ((self.shards, "shards-job.yaml"), (self.merge, "merge-job.yaml")):
            with self.subTest(job=name):
                volumes, c = self.check_job(job, name)
                claims = {n: v["persistentVolumeClaim"]["claimName"] for n, v in volumes.items()
                          if "persistentVolumeClaim" in v}
                self.assertEqual(list(claims.values()), [claim])
                mounts = [m["mountPath"] for m in c["volumeMounts"] if m["name"] in claims]
                self.assertEqual(len(mounts), 1)
                for key, value in env_of(job).items():
                    if key in ("TILTH_AB_RECORDINGS", "TILTH_AB_VARIANTS", "TILTH_AB_OUT",
                               "TILTH_AB_REPORT"):
                        for path in value.split():
                            self.assertTrue(path.startswith(mounts[0].rstrip("/") + "/"),
                                            "%s=%s is not on the volume at %s"
                                            % (key, path, mounts[0]))

    def test_the_jobs_commands_give_the_single_run(self):
        """Each container's command as its pod would run it, on the fixture."""
        folder = tempfile.mkdtemp(prefix="tilth-fleet-k8s-")
        self.addCleanup(shutil.rmtree, folder)
        shards = self.shards["spec"]["completions"]
        out = os.path.join(folder, "ab-out")
        fixture = fleet_environment(out, shards)

        def run(job, **extra):
            c = container(job)
            env = {k: v for k, v in os.environ.items() if not k.startswith("TILTH_AB_")}
            env.update(env_of(job))
            # The fixture's paths for /data; TILTH the program built here.
            env.update({k: fixture[k] for k in env_of(job) if k in fixture})
            env.update(TILTH=fixture["TILTH"], **extra)
            if "TILTH_AB_REPORT" in env:
                env["TILTH_AB_REPORT"] = os.path.join(out, "report")
            return subprocess.run(c["command"], env=env, capture_output=True, text=True,
                                  timeout=150, cwd=folder)

        for index in range(shards):
            result = run(self.shards, JOB_COMPLETION_INDEX=str(index))
            self.assertEqual(result.returncode, 0, result.stderr)
        result = run(self.merge)
        self.assertEqual(result.returncode, 0, result.stderr)
        assert_same_as_single_run(self, os.path.join(out, "report"))
        # A rerun of one index (submit.sh rerun I) and the merge again over the report.
        result = run(self.shards, JOB_COMPLETION_INDEX="0", TILTH_AB_INDEX=str(shards - 1))
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertIn("shard %d/%d" % (shards - 1, shards), result.stdout)
        result = run(self.merge)
        self.assertEqual(result.returncode, 0, result.stderr)
        assert_same_as_single_run(self, os.path.join(out, "report"))


if __name__ == "__main__":
    unittest.main()

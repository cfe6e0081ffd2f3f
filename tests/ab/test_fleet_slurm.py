"""deploy/fleet/slurm on a real single-node Slurm cluster (Debian's slurmctld, slurmd and
munge, started here as child processes with their configuration, state and keys in a
temporary folder): submit.sh submits the fixture's comparison (make_fixture.py) as a
job array of 3 shards, at most 2 at a time, and the merge after it; every task and the
merge complete and the merged report is the single run's, apart from timings."""
import os
import re
import shutil
import socket
import subprocess
import sys
import tempfile
import time
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "support"))
from ports import free_port  # noqa: E402
from processes import interrupt, start_logged  # noqa: E402

from fleet_support import SLURM, TILTH, assert_same_as_single_run, fleet_environment  # noqa: E402

SHARDS = 3
ATTEMPTS = 3


class PortTaken(RuntimeError):
    pass
TIMEOUT = 120  # seconds for the array and the merge to end


def tail(path, lines=30):
    try:
        with open(path, errors="replace") as f:
            return "".join(f.readlines()[-lines:])
    except OSError:
        return "(no %s)" % path


class SlurmClusterTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        # The daemons' ports are free when chosen (below the ephemeral range, which no
        # outgoing connection takes) but another test may choose one too before a daemon
        # binds it: then the cluster starts again on other ports.
        for attempt in range(ATTEMPTS):
            cls.folder = tempfile.mkdtemp(prefix="tilth-fleet-slurm-")
            cls.daemons = []
            try:
                cls.start_cluster()
                return
            except PortTaken:
                cls.tearDownClass()
            except BaseException:
                cls.tearDownClass()
                raise
        raise RuntimeError("the cluster's ports were taken %d times over" % ATTEMPTS)

    @classmethod
    def start_cluster(cls):
        f = cls.folder
        for sub in ("munge", "state", "spool", "log"):
            os.makedirs(os.path.join(f, sub))
        os.chmod(f, 0o755)
        os.chmod(os.path.join(f, "munge"), 0o755)  # clients reach the socket in it
        key = os.path.join(f, "munge.key")
        with open(key, "wb") as out:
            out.write(os.urandom(1024))
        os.chmod(key, 0o600)
        socket_path = os.path.join(f, "munge", "munge.socket")
        host = socket.gethostname().split(".")[0]
        cls.conf = os.path.join(f, "slurm.conf")
        with open(cls.conf, "w") as out:
            out.write("\n".join([
                "ClusterName=tilthtest",
                "SlurmctldHost=%s(127.0.0.1)" % host,
                "SlurmctldPort=%d" % free_port(), "SlurmdPort=%d" % free_port(),
                "SlurmUser=root", "SlurmdUser=root",
                "AuthType=auth/munge", "CredType=cred/munge",
                "AuthInfo=socket=" + socket_path,
                "StateSaveLocation=" + os.path.join(f, "state"),
                "SlurmdSpoolDir=" + os.path.join(f, "spool"),
                "SlurmctldPidFile=" + os.path.join(f, "slurmctld.pid"),
                "SlurmdPidFile=" + os.path.join(f, "slurmd.pid"),
                "SlurmctldLogFile=" + os.path.join(f, "log", "slurmctld.log"),
                "SlurmdLogFile=" + os.path.join(f, "log", "slurmd.log"),
                "ProctrackType=proctrack/linuxproc", "TaskPlugin=task/none",
                "JobAcctGatherType=jobacct_gather/none",
                "AccountingStorageType=accounting_storage/none", "JobCompType=jobcomp/none",
                "MpiDefault=none", "SchedulerType=sched/builtin",
                "SelectType=select/cons_tres", "SelectTypeParameters=CR_Core",
                "ReturnToService=2", "MinJobAge=600",
                "NodeName=%s NodeAddr=127.0.0.1 CPUs=2 RealMemory=1000 State=UNKNOWN" % host,
                "PartitionName=debug Nodes=%s Default=YES MaxTime=INFINITE State=UP" % host,
                ""]))
        cls.env = dict(os.environ, SLURM_CONF=cls.conf, MUNGE_SOCKET=socket_path)
        log = lambda name: os.path.join(f, "log", name)  # noqa: E731
        cls.daemons.append(start_logged(
            ["munged", "--foreground", "--force", "--socket=" + socket_path, "--key-file=" + key,
             "--log-file=" + log("munged.log"), "--pid-file=" + os.path.join(f, "munged.pid"),
             "--seed-file=" + os.path.join(f, "munged.seed")], log("munged.out")))
        cls.wait_for(lambda: os.path.exists(socket_path), "munged's socket", log("munged.out"))
        os.environ["SLURM_CONF"] = cls.conf  # start_logged passes the environment on
        cls.daemons.append(start_logged(["slurmctld", "-D", "-f", cls.conf], log("slurmctld.out")))
        cls.daemons.append(start_logged(["slurmd", "-D", "-f", cls.conf], log("slurmd.out")))

        def node_idle():
            result = cls.slurm(["sinfo", "-h", "-o", "%T"], check=False)
            return result.returncode == 0 and result.stdout.strip() == "idle"
        cls.wait_for(node_idle, "the node idle in sinfo", log("slurmctld.log"))

    @classmethod
    def wait_for(cls, condition, what, log, seconds=30):
        deadline = time.monotonic() + seconds
        while not condition():
            for daemon in cls.daemons:
                if daemon.poll() is not None:
                    logs = [os.path.join(cls.folder, "log", name)
                            for name in ("slurmctld.log", "slurmd.log")]
                    taken = any("Address already in use" in tail(path) for path in logs)
                    problem = PortTaken if taken else RuntimeError
                    raise problem("%s exited (%d) waiting for %s:\n%s" % (
                        daemon.args, daemon.returncode, what, tail(log)))
            if time.monotonic() > deadline:
                raise RuntimeError("no %s after %d s:\n%s" % (what, seconds, tail(log)))
            time.sleep(0.5)

    @classmethod
    def slurm(cls, command, check=True):
        result = subprocess.run(command, env=cls.env, capture_output=True, text=True,
                                timeout=30)
        if check and result.returncode != 0:
            raise RuntimeError("%s: %s" % (" ".join(command), result.stderr))
        return result

    @classmethod
    def tearDownClass(cls):
        if len(cls.daemons) == 3:
            subprocess.run(["scancel", "--user=root"], env=cls.env, capture_output=True,
                           timeout=30)
        for daemon in reversed(cls.daemons):  # slurmd, slurmctld, munged, each by its pid
            interrupt(daemon, seconds=15)
        os.environ.pop("SLURM_CONF", None)
        shutil.rmtree(cls.folder, ignore_errors=True)

    def job_states(self, job):
        """{job id (array tasks as ID_I): (state, exit code)} of `job`."""
        text = self.slurm(["scontrol", "-o", "show", "job", job]).stdout
        states = {}
        for line in text.splitlines():
            fields = dict(re.findall(r"(\w+)=(\S*)", line))
            name = fields["JobId"]
            if fields.get("ArrayTaskId"):
                name = fields["ArrayJobId"] + "_" + fields["ArrayTaskId"]
            states[name] = (fields["JobState"], fields["ExitCode"])
        return states

    def test_array_and_merge_give_the_single_run(self):
        out = os.path.join(self.folder, "shared", "ab")
        env = fleet_environment(out, SHARDS)
        options = env["TILTH_AB_OPTIONS"].split()
        started = time.monotonic()
        result = subprocess.run(
            ["bash", os.path.join(SLURM, "submit.sh"), "--shards", str(SHARDS), "--parallel", "2",
             "--cpus", "1", "--variants", env["TILTH_AB_VARIANTS"], "--out", out,
             "--tilth", TILTH, env["TILTH_AB_RECORDINGS"], "--", *options],
            env=self.env, capture_output=True, text=True, timeout=60, cwd=self.folder)
        self.assertEqual(result.returncode, 0, result.stderr)
        ids = re.search(r"array (\d+) \(3 shards, --array=0-2%2\), merge (\d+) afterok",
                        result.stdout)
        self.assertIsNotNone(ids, result.stdout)
        array, merge = ids.groups()

        done = ("COMPLETED", "FAILED", "CANCELLED", "TIMEOUT", "NODE_FAIL", "OUT_OF_MEMORY")
        deadline = time.monotonic() + TIMEOUT
        while True:
            states = {**self.job_states(array), **self.job_states(merge)}
            if all(state in done for state, _ in states.values()) and len(states) == SHARDS + 1:
                break
            if time.monotonic() > deadline:
                self.fail("not done after %d s: %s\n%s" % (
                    TIMEOUT, states, tail(os.path.join(self.folder, "log", "slurmctld.log"))))
            time.sleep(1)
        logs = "".join(tail(os.path.join(out, "logs", name))
                       for name in sorted(os.listdir(os.path.join(out, "logs"))))
        expected = {"%s_%d" % (array, i): ("COMPLETED", "0:0") for i in range(SHARDS)}
        expected[merge] = ("COMPLETED", "0:0")
        self.assertEqual(states, expected, logs)
        print("array and merge done in %.1f s" % (time.monotonic() - started), file=sys.stderr)

        self.assertEqual(sorted(os.listdir(out)),
                         ["logs", "report"] + ["shard-%d" % i for i in range(SHARDS)])
        for i in range(SHARDS):
            self.assertIn("tilth-ab shard %d/%d" % (i, SHARDS),
                          tail(os.path.join(out, "logs", "shard-%d.out" % i)))
        assert_same_as_single_run(self, os.path.join(out, "report"))


if __name__ == "__main__":
    unittest.main()

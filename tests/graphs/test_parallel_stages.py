"""Every stage that declares itself parallel (frames run through it concurrently) run with
several frames in flight gives, frame for frame, the distances it gives with one frame
at a time. The graph is made from what `tilth plugins` lists, so a new parallel stage
this test does not know how to wire fails it instead of going unchecked. Run by the
`tsan` preset too, where ThreadSanitizer stops `tilth` at the first data race
(docs/reliability.md). The recording and the model the graph reads are made first, with
ThreadSanitizer's reports off: the simulator renders in OpenCV's parallel_for_, whose
bodies run on oneTBB's uninstrumented threads, which ThreadSanitizer cannot judge.
"""
import csv
import json
import os
import re
import shutil
import subprocess
import tempfile
import unittest

TILTH = os.environ["TILTH_BIN"]
FRAMES = 12
IN_FLIGHT = 4
# `tilth plugins` lists a stage as "  TYPE  description  (in: PORTS; out: PORTS)".
STAGE_LINE = re.compile(r"^  (\S+)  .*\(in: (.*); out: (.*)\)$")


def tilth(*arguments, timeout=600, env=None):
    done = subprocess.run([TILTH, *arguments], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                          text=True, timeout=timeout, env=env)
    if done.returncode != 0:
        raise AssertionError("tilth %s failed (%d): %s"
                             % (" ".join(arguments), done.returncode, done.stderr[-4000:]))
    return done.stdout


def parallel_stages():
    """{type: (inputs, outputs)} of every parallel stage, ports as "name:message type"."""
    stages = {}
    for line in tilth("plugins").splitlines():
        match = STAGE_LINE.match(line)
        if match and "parallel" in tilth("describe", match[1]).splitlines()[1]:
            stages[match[1]] = (match[2], match[3])
    return stages


def segmenters_and_estimators(stages):
    """The parallel stages by role; fails on one that fits none this test wires."""
    segmenters = [t for t, (ins, _) in stages.items() if ins.startswith("color:tilth.RegisteredColor")]
    estimators = [t for t, (ins, _) in stages.items() if ins.startswith("soil_depth:")]
    wired = {"depth.projection", "registration.projective", *segmenters, *estimators}
    unknown = sorted(set(stages) - wired)
    assert not unknown, "parallel stages this test does not run (wire them in): %s" % unknown
    return segmenters, estimators


def preparing():
    """The environment of a preparation step: ThreadSanitizer's reports off."""
    return dict(os.environ, TSAN_OPTIONS=os.environ.get("TSAN_OPTIONS", "") + " report_bugs=0")


def chain_graph(segmenters, estimators, recording, model, csv_folder, in_flight):
    """The recording through depth projection and registration into every segmenter, and
    each segmenter's soil depth into every estimator, each pair to its own CSV."""
    nodes = {
        "scene": {"type": "recording.image_folder", "params": {"path": recording}},
        "project": {"type": "depth.projection"},
        "register": {"type": "registration.projective"},
    }
    edges = [["scene.raw", "project.raw"], ["scene.color", "register.color"],
             ["project.depth", "register.depth"]]
    for segmenter in segmenters:
        segment = segmenter.replace(".", "_")
        params = {"model": model} if segmenter == "segmentation.pixel_classifier" else {}
        nodes[segment] = {"type": segmenter, "params": params}
        edges += [["register.color", segment + ".color"], ["project.depth", segment + ".depth"]]
        for estimator in estimators:
            name = segment + "__" + estimator.replace(".", "_")
            nodes[name] = {"type": estimator}
            nodes[name + "_csv"] = {"type": "sinks.csv",
                                    "params": {"path": os.path.join(csv_folder, name + ".csv")}}
            edges += [[segment + ".soil_depth", name + ".soil_depth"],
                      ["register.color", name + ".color"],
                      [name + ".distance", name + "_csv.distance"],
                      ["scene.truth", name + "_csv.truth"]]
    return {"nodes": nodes, "edges": edges,
            "runtime": {"max_in_flight": in_flight, "when_full": "block", "on_error": "stop"}}


# Every column of sinks.csv that the measurement decides (not its timing).
MEASURED = ("index", "distance_mm", "valid", "cause", "soil_fraction", "soil_pixels",
            "spread_mm", "confidence")


def measured(csv_folder):
    """{CSV name: [the MEASURED columns of each row]}"""
    result = {}
    for name in sorted(os.listdir(csv_folder)):
        with open(os.path.join(csv_folder, name)) as f:
            result[name] = [[row[column] for column in MEASURED] for row in csv.DictReader(f)]
    return result


class ParallelStages(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="tilth-parallel-")
        cls.stages = parallel_stages()
        cls.segmenters, cls.estimators = segmenters_and_estimators(cls.stages)
        cls.recording = os.path.join(cls.tmp, "field")
        tilth("simulate", cls.recording, "--preset", "field", "--frames", str(FRAMES),
              env=preparing())
        cls.model = os.path.join(cls.tmp, "model.yml.gz")
        tilth("train-segmenter", cls.recording, "--out", cls.model, "--trees", "5",
              "--samples", "300", env=preparing())

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def run_chain(self, in_flight):
        folder = os.path.join(self.tmp, "in_flight_%d" % in_flight)
        os.makedirs(folder)
        graph = os.path.join(self.tmp, "parallel_%d.json" % in_flight)
        with open(graph, "w") as f:
            json.dump(chain_graph(self.segmenters, self.estimators, self.recording, self.model, folder,
                                 in_flight), f, indent=1)
        tilth("run", graph, "--quiet")
        return measured(folder)

    def test_the_project_has_parallel_stages_of_each_kind(self):
        for expected in ("depth.projection", "registration.projective",
                         "segmentation.fusion", "estimation.ground_plane"):
            self.assertIn(expected, self.stages)

    def test_frames_in_flight_together_measure_what_frames_one_at_a_time_do(self):
        alone, together = self.run_chain(1), self.run_chain(IN_FLIGHT)
        pairs = len(self.segmenters) * len(self.estimators)
        self.assertEqual((len(alone), len(together)), (pairs, pairs))
        for name, rows in together.items():
            with self.subTest(csv=name):
                self.assertEqual(len(rows), FRAMES)
                self.assertEqual(rows, alone[name])
        valid = sum(row[2] == "1" for rows in together.values() for row in rows)
        self.assertGreater(valid, 0, "every frame invalid: the comparison says nothing")


if __name__ == "__main__":
    unittest.main()

"""The numbers of a `tilth ab` report (made by make_fixture.py) recomputed independently:
the ground truth read from the recordings' own files (frames.csv, mask PNGs with
OpenCV), the predicted masks from the images the run kept, the statistics with Python's
statistics module and scipy's Student t. Also: the same numbers from a second run with
one graph at a time, the base variant equal to graphs/paper.json, the ranking of the
overlay frames, and the issue's bar for the best variant."""
import csv
import json
import math
import os
import re
import statistics
import unittest

import cv2
import numpy as np
from scipy import stats

FIXTURE = os.environ["AB_FIXTURE"]
REPORT = os.path.join(FIXTURE, "report")
SERIAL = os.path.join(FIXTURE, "report-serial")
VARIANTS = ["threshold", "wide", "plane"]
# recording name in the report -> the image folder holding its truth
TRUTH_FOLDERS = {
    "case_c": os.path.join(FIXTURE, "recordings", "case_c"),
    "case_c_hidden": os.path.join(FIXTURE, "recordings", "case_c_hidden"),
    "case_c_mcap": os.path.join(FIXTURE, "recordings", "case_c"),  # converted from it
}
NO_SOIL_BELOW = 0.01


def close(a, b, tolerance=1e-9):
    if a is None or b is None:
        return a is None and b is None
    return math.isclose(a, b, rel_tol=tolerance, abs_tol=tolerance)


def number(text):
    return float(text) if text != "" else None


def read_truth(folder):
    """frame id -> (truth distance or None, truth mask or None), from the recording."""
    truth = {}
    with open(os.path.join(folder, "frames.csv")) as f:
        for row in csv.DictReader(f):
            mask = None
            if row.get("mask"):
                mask = cv2.imread(os.path.join(folder, row["mask"]), cv2.IMREAD_UNCHANGED)
            truth[int(row["index"])] = (number(row.get("ground_truth_mm", "")), mask)
    return truth


def segmented_region(shape):
    """What every variant here segments: the chain's roi, the middle half of the image in
    each direction, and 8 px around it (docs/segmentation.md, "The region segmented")."""
    rows, cols = shape
    top, left = (rows - rows // 2) // 2 - 8, (cols - cols // 2) // 2 - 8
    return slice(max(top, 0), min(top + rows // 2 + 16, rows)), \
        slice(max(left, 0), min(left + cols // 2 + 16, cols))


def mask_counts(predicted, truth):
    """Over the pixels segmented, as sinks.evaluation counts them."""
    region = segmented_region(truth.shape)
    predicted, truth = predicted[region], truth[region]
    known = (truth == 0) | (truth == 255)
    residue = predicted == 255
    truly = truth == 255
    return {"tp": int(np.sum(known & residue & truly)),
            "fp": int(np.sum(known & residue & ~truly)),
            "fn": int(np.sum(known & ~residue & truly)),
            "tn": int(np.sum(known & ~residue & ~truly)),
            "unknown": int(np.sum(known & (predicted == 128)))}


def error_figures(errors):
    n = len(errors)
    if n == 0:
        return {"count": 0}
    figures = {"count": n, "mean_mm": statistics.fmean(errors),
               "mean_abs_mm": statistics.fmean(abs(e) for e in errors),
               "max_abs_mm": max(abs(e) for e in errors),
               "rms_mm": math.sqrt(statistics.fmean(e * e for e in errors)),
               "std_mm": None, "ci95_low_mm": None, "ci95_high_mm": None}
    if n > 1:
        std = statistics.stdev(errors)
        half = stats.t.ppf(0.975, n - 1) * std / math.sqrt(n)
        figures.update(std_mm=std, ci95_low_mm=figures["mean_mm"] - half,
                       ci95_high_mm=figures["mean_mm"] + half)
    return figures


def ratio(a, b):
    return a / b if b else None


class Recomputed:
    """Every frame of every job, judged from the recordings' truth and the kept masks."""

    def __init__(self):
        self.truth = {name: read_truth(folder) for name, folder in TRUTH_FOLDERS.items()}
        with open(os.path.join(REPORT, "frames.csv")) as f:
            self.rows = list(csv.DictReader(f))
        self.frames = {}  # (variant, recording) -> [judged frame]
        for row in self.rows:
            self.frames.setdefault((row["variant"], row["recording"]), []).append(self.judge(row))

    def judge(self, row):
        frame_id = int(row["frame_id"])
        truth_mm, truth_mask = self.truth[row["recording"]][frame_id]
        soil = None if truth_mask is None else float(np.mean(truth_mask == 0))
        valid = row["valid"] == "1"
        distance = number(row["distance_mm"])
        expected = ("no_visible_soil" if soil is not None and soil < NO_SOIL_BELOW
                    else "valid" if truth_mm is not None else "unknown")
        mask = None
        mask_file = os.path.join(REPORT, "runs", row["variant"], row["recording"], "frames.images",
                                 "mask", "%06d.png" % frame_id)
        if truth_mask is not None and os.path.exists(mask_file):
            mask = mask_counts(cv2.imread(mask_file, cv2.IMREAD_UNCHANGED), truth_mask)
        return {"row": row, "frame_id": frame_id, "truth_mm": truth_mm, "soil": soil,
                "valid": valid, "distance": distance, "expected": expected,
                "error": distance - truth_mm if valid and truth_mm is not None else None,
                "missed": expected == "valid" and not valid,
                "false_valid": expected == "no_visible_soil" and valid, "mask": mask}

    def figures(self, jobs):
        frames = [frame for job in jobs for frame in self.frames[job]]
        masks = [frame["mask"] for frame in frames if frame["mask"] is not None]
        total = {key: sum(m[key] for m in masks) for key in ("tp", "fp", "fn", "tn", "unknown")}
        return {
            "frames": len(frames),
            "valid": sum(f["valid"] for f in frames),
            "expected_valid": sum(f["expected"] == "valid" for f in frames),
            "no_visible_soil": sum(f["expected"] == "no_visible_soil" for f in frames),
            "missed": sum(f["missed"] for f in frames),
            "false_valid": sum(f["false_valid"] for f in frames),
            "error": error_figures([f["error"] for f in frames if f["error"] is not None]),
            "mask": None if not masks else dict(
                total, frames=len(masks), iou=ratio(total["tp"], total["tp"] + total["fp"] + total["fn"]),
                precision=ratio(total["tp"], total["tp"] + total["fp"]),
                recall=ratio(total["tp"], total["tp"] + total["fn"])),
        }


RECOMPUTED = Recomputed()


def load_summary(folder):
    with open(os.path.join(folder, "summary.json")) as f:
        return json.load(f)


class FrameTest(unittest.TestCase):
    def test_every_job_has_every_frame(self):
        for variant in VARIANTS:
            for recording, truth in RECOMPUTED.truth.items():
                ids = [f["frame_id"] for f in RECOMPUTED.frames[(variant, recording)]]
                self.assertEqual(ids, sorted(truth), (variant, recording))

    def test_frames_match_the_recordings_truth(self):
        for frame in (f for frames in RECOMPUTED.frames.values() for f in frames):
            row = frame["row"]
            where = (row["variant"], row["recording"], frame["frame_id"])
            self.assertTrue(close(number(row["truth_mm"]), frame["truth_mm"]), where)
            self.assertTrue(close(number(row["truth_soil_fraction"]), frame["soil"], 1e-12), where)
            self.assertEqual(row["expected"], frame["expected"], where)
            self.assertTrue(close(number(row["error_mm"]), frame["error"]), where)
            self.assertEqual(row["missed"] == "1", frame["missed"], where)
            self.assertEqual(row["false_valid"] == "1", frame["false_valid"], where)
            self.assertEqual(row["valid"] == "1", row["distance_mm"] != "", where)

    def test_mask_counts_match_the_masks(self):
        checked = 0
        for frame in (f for frames in RECOMPUTED.frames.values() for f in frames):
            row = frame["row"]
            if frame["mask"] is None:  # the frame whose truth was removed
                self.assertEqual((row["recording"], frame["frame_id"]), ("case_c_hidden", 2))
                self.assertEqual(row["mask_tp"], "")
                continue
            for key, value in frame["mask"].items():
                self.assertEqual(int(row["mask_" + key]), value, (row, key))
            checked += 1
        self.assertEqual(checked, len(VARIANTS) * (3 * len(TRUTH_FOLDERS) - 1))

    def test_edited_truth_is_judged(self):
        """case_c_hidden: frame 1 has no visible soil, frame 2 no truth."""
        for variant in VARIANTS:
            frames = RECOMPUTED.frames[(variant, "case_c_hidden")]
            self.assertEqual([f["expected"] for f in frames], ["valid", "no_visible_soil", "unknown"])
            self.assertEqual(frames[1]["row"]["false_valid"], "1" if frames[1]["valid"] else "0")
            self.assertEqual(frames[2]["row"]["truth_mm"], "")

    def test_mcap_replay_equals_the_image_folder(self):
        for variant in VARIANTS:
            for folder, mcap in zip(RECOMPUTED.frames[(variant, "case_c")],
                                    RECOMPUTED.frames[(variant, "case_c_mcap")]):
                for key in ("frame_id", "time_s", "valid", "distance_mm", "truth_mm", "mask_tp",
                            "mask_fp", "mask_fn", "mask_tn"):
                    self.assertEqual(folder["row"][key], mcap["row"][key], (variant, key))

    def test_base_variant_equals_graphs_paper_json(self):
        with open(os.path.join(FIXTURE, "paper-case_c.csv")) as f:
            paper = {int(row["index"]): row for row in csv.DictReader(f)}
        frames = RECOMPUTED.frames[("threshold", "case_c")]
        self.assertEqual([f["frame_id"] for f in frames], sorted(paper))
        for frame in frames:
            row = paper[frame["frame_id"]]
            self.assertEqual(frame["valid"], row["valid"] == "1")
            if frame["valid"]:
                self.assertAlmostEqual(frame["distance"], float(row["distance_mm"]), delta=0.0005)


class SummaryTest(unittest.TestCase):
    def assert_figures(self, reported, expected, where):
        for key in ("frames", "valid", "expected_valid", "no_visible_soil", "missed", "false_valid"):
            self.assertEqual(reported[key], expected[key], (where, key))
        for key, value in expected["error"].items():
            self.assertTrue(close(reported["error"][key], value),
                            (where, key, reported["error"][key], value))
        if expected["mask"] is None:
            self.assertIsNone(reported["mask"], where)
            return
        for key, value in expected["mask"].items():
            self.assertTrue(close(reported["mask"][key], value), (where, "mask", key))

    def test_the_report_names_its_format_and_release(self):
        with open(os.path.join(os.environ["TILTH_SOURCE_DIR"], "CMakeLists.txt")) as f:
            release = re.search(r"project\(Tilth VERSION ([0-9.]+)", f.read()).group(1)
        summary = load_summary(REPORT)
        self.assertEqual(summary["format"], "tilth-ab/1")
        self.assertEqual(summary["tilth_version"], release)

    def test_per_recording_figures(self):
        summary = load_summary(REPORT)
        rows = summary["recording_figures"]
        self.assertEqual(len(rows), len(VARIANTS) * len(TRUTH_FOLDERS))
        for row in rows:
            self.assertFalse(row["failed"], row)
            where = (row["variant"], row["recording"])
            self.assert_figures(row["figures"], RECOMPUTED.figures([where]), where)

    def test_pooled_figures(self):
        summary = load_summary(REPORT)
        self.assertEqual([v["variant"] for v in summary["variant_figures"]], VARIANTS)
        for row in summary["variant_figures"]:
            jobs = [(row["variant"], recording) for recording in sorted(TRUTH_FOLDERS)]
            self.assert_figures(row["figures"], RECOMPUTED.figures(jobs), row["variant"])
            self.assertTrue(row["stage_times"], row["variant"])
            self.assertEqual({s["node"] for s in row["stage_times"]},
                             {"project", "register", "segment", "estimate"})

    def test_summary_csv_repeats_the_json(self):
        summary = load_summary(REPORT)
        figures = {(r["variant"], r["recording"]): r["figures"] for r in summary["recording_figures"]}
        for r in summary["variant_figures"]:
            figures[(r["variant"], "*")] = r["figures"]
        with open(os.path.join(REPORT, "summary.csv")) as f:
            rows = list(csv.DictReader(f))
        self.assertEqual(len(rows), len(figures))
        for row in rows:
            expected = figures[(row["variant"], row["recording"])]
            self.assertEqual(int(row["missed"]), expected["missed"])
            self.assertEqual(int(row["false_valid"]), expected["false_valid"])
            self.assertTrue(close(number(row["error_mean_mm"]), expected["error"].get("mean_mm")))
            self.assertTrue(close(number(row["error_ci95_low_mm"]),
                                  expected["error"].get("ci95_low_mm")))
            self.assertTrue(close(number(row["mask_iou"]), (expected["mask"] or {}).get("iou")))

    def test_histogram_holds_every_error_in_its_bin(self):
        histogram = load_summary(REPORT)["error_histogram"]
        first, width = histogram["first_edge_mm"], histogram["width_mm"]
        for variant in VARIANTS:
            errors = [f["error"] for r in TRUTH_FOLDERS for f in RECOMPUTED.frames[(variant, r)]
                      if f["error"] is not None]
            counts = [0] * histogram["bins"]
            for error in errors:
                counts[min(int(math.floor((error - first) / width)), histogram["bins"] - 1)] += 1
            self.assertEqual(histogram["counts"][variant], counts, variant)

    def test_overlay_frames_are_where_variants_disagree_most(self):
        summary = load_summary(REPORT)
        for entry in summary["disagreements"]:
            recording = entry["recording"]
            ranked = []
            for frame_id in sorted(RECOMPUTED.truth[recording]):
                frames = [next(f for f in RECOMPUTED.frames[(v, recording)] if f["frame_id"] == frame_id)
                          for v in VARIANTS]
                valid = [f["distance"] for f in frames if f["valid"]]
                errors = [abs(f["error"]) for f in frames if f["error"] is not None]
                ranked.append(((0 < len(valid) < len(frames),
                                max(valid) - min(valid) if valid else 0.0,
                                max(errors, default=0.0)), frame_id))
            ranked.sort(key=lambda item: item[0], reverse=True)  # stable: frame order among equals
            self.assertEqual([f["frame_id"] for f in entry["frames"]],
                             [frame_id for _, frame_id in ranked[:2]], recording)

    def test_same_inputs_give_the_same_numbers(self):
        with open(os.path.join(REPORT, "frames.csv")) as a, open(os.path.join(SERIAL, "frames.csv")) as b:
            self.assertEqual(a.read(), b.read())

        def without_times(summary):
            for row in summary["variant_figures"] + summary["recording_figures"]:
                row.pop("stage_times")
                row.pop("frames_per_second", None)
            return summary

        self.assertEqual(without_times(load_summary(REPORT)), without_times(load_summary(SERIAL)))
        self.assertFalse(os.path.exists(os.path.join(SERIAL, "runs", "wide", "case_c", "images")),
                         "images are removed without --keep-images")

    def test_best_variant_meets_the_issue_bar(self):
        """The best variant's mean |error| on the paper's case C is <= 1 mm, none missed."""
        best = min(VARIANTS, key=lambda v: RECOMPUTED.figures([(v, "case_c")])["error"]["mean_abs_mm"])
        figures = RECOMPUTED.figures([(best, "case_c")])
        self.assertLessEqual(figures["error"]["mean_abs_mm"], 1.0, best)
        self.assertEqual(figures["missed"], 0, best)

if __name__ == "__main__":
    unittest.main()

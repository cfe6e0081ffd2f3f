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
BASELINE = "wide"  # --baseline in make_fixture.py
# recording -> tags: recording.json's, and tags.csv's over them (make_fixture.py)
TAGS = {"case_c": {"site": "north", "light": "sun"},
        "case_c_hidden": {"site": "south", "light": "sun"},
        "case_c_mcap": {}}
COVER_BINS = [(0.0, 0.25, "0-25 %"), (0.25, 0.5, "25-50 %"), (0.5, 0.75, "50-75 %"),
              (0.75, 0.9, "75-90 %"), (0.9, 1.01, "90-100 %")]


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


def t_interval(values):
    """mean -/+ t(0.975, n-1) s / sqrt(n), the one 95 % interval of a report."""
    mean = statistics.fmean(values)
    if len(values) < 2:
        return mean, None, None
    half = stats.t.ppf(0.975, len(values) - 1) * statistics.stdev(values) / math.sqrt(len(values))
    return mean, mean - half, mean + half


def error_figures(errors):
    n = len(errors)
    if n == 0:
        return {"frames_with_error_value": 0}
    mean, low, high = t_interval(errors)
    return {"frames_with_error_value": n, "mean_mm": mean,
            "mean_abs_mm": statistics.fmean(abs(e) for e in errors),
            "max_abs_mm": max(abs(e) for e in errors),
            "rms_mm": math.sqrt(statistics.fmean(e * e for e in errors)),
            "std_mm": statistics.stdev(errors) if n > 1 else None,
            "mean_ci95_low_mm": low, "mean_ci95_high_mm": high}


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

    def figures(self, jobs, keep=lambda recording, frame: True):
        frames = [frame for job in jobs for frame in self.frames[job] if keep(job[1], frame)]
        masks = [frame["mask"] for frame in frames if frame["mask"] is not None]
        total = {key: sum(m[key] for m in masks) for key in ("tp", "fp", "fn", "tn", "unknown")}
        return {
            "frames": len(frames),
            "frames_valid": sum(f["valid"] for f in frames),
            "frames_expected_valid": sum(f["expected"] == "valid" for f in frames),
            "frames_without_visible_soil": sum(f["expected"] == "no_visible_soil" for f in frames),
            "frames_missed": sum(f["missed"] for f in frames),
            "frames_false_valid": sum(f["false_valid"] for f in frames),
            "error": error_figures([f["error"] for f in frames if f["error"] is not None]),
            "mask": None if not masks else {
                "frames_with_both_masks": len(masks),
                "px_residue_called_residue": total["tp"],
                "px_soil_called_residue": total["fp"],
                "px_residue_called_soil_or_unknown": total["fn"],
                "px_soil_called_soil_or_unknown": total["tn"],
                "px_called_unknown": total["unknown"],
                "residue_iou": ratio(total["tp"], total["tp"] + total["fp"] + total["fn"]),
                "residue_precision": ratio(total["tp"], total["tp"] + total["fp"]),
                "residue_recall": ratio(total["tp"], total["tp"] + total["fn"])},
        }

    def paired(self, variant, recordings, keep=lambda recording, frame: True):
        """Against the baseline: per recording the mean of |error| - |baseline's|
        over the frames with both, then the t interval over those recordings' means."""
        means, frames = [], 0
        missed_variant = missed_baseline = 0
        for recording in recordings:
            base = {f["frame_id"]: f for f in self.frames[(BASELINE, recording)]
                    if keep(recording, f)}
            differences = []
            for frame in self.frames[(variant, recording)]:
                if frame["frame_id"] not in base:
                    continue
                other = base[frame["frame_id"]]
                missed_variant += frame["missed"] and not other["missed"]
                missed_baseline += other["missed"] and not frame["missed"]
                if frame["error"] is not None and other["error"] is not None:
                    differences.append(abs(frame["error"]) - abs(other["error"]))
            if differences:
                means.append(statistics.fmean(differences))
                frames += len(differences)
        mean, low, high = t_interval(means) if means else (None, None, None)
        if variant == BASELINE:
            verdict = "baseline"
        elif low is None:
            verdict = "too few recordings to tell"
        else:
            verdict = ("closer to the truth" if high < 0 else "farther from the truth" if low > 0
                       else "no clear difference")
        return {"baseline": BASELINE, "frames_with_both_error_values": frames,
                "recordings": len(means), "abs_error_difference_mm": mean,
                "abs_error_difference_ci95_low_mm": low, "abs_error_difference_ci95_high_mm": high,
                "verdict": verdict, "frames_missed_by_variant_only": missed_variant,
                "frames_missed_by_baseline_only": missed_baseline}


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
        for key in ("frames", "frames_valid", "frames_expected_valid",
                    "frames_without_visible_soil", "frames_missed", "frames_false_valid"):
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
        self.assertEqual(summary["format"], "tilth-ab/2")
        self.assertEqual(summary["tilth_version"], release)

    def test_the_report_is_stamped_with_how_it_was_made(self):
        made = load_summary(REPORT)["made"]
        self.assertEqual(made["tilth_version"], load_summary(REPORT)["tilth_version"])
        self.assertRegex(made["date_utc"], r"^\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ$")
        self.assertEqual(made["command_line"][:2], ["tilth", "ab"])
        self.assertIn("--keep-images", made["command_line"])
        self.assertEqual(made["command_line"][-1], "--keep-images")
        self.assertEqual(made["shard_command_lines"], [])
        with open(os.path.join(REPORT, "report.html")) as f:
            html = f.read()
        self.assertIn(made["date_utc"], html)
        self.assertIn("--baseline wide", html)

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
            self.assertEqual(int(row["frames_missed"]), expected["frames_missed"])
            self.assertEqual(int(row["frames_false_valid"]), expected["frames_false_valid"])
            self.assertEqual(int(row["frames_with_error_value"]),
                             expected["error"]["frames_with_error_value"])
            self.assertTrue(close(number(row["error_mean_mm"]), expected["error"].get("mean_mm")))
            self.assertTrue(close(number(row["error_mean_ci95_low_mm"]),
                                  expected["error"].get("mean_ci95_low_mm")))
            self.assertTrue(close(number(row["residue_iou"]),
                                  (expected["mask"] or {}).get("residue_iou")))

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
            summary.pop("made")
            return summary

        self.assertEqual(without_times(load_summary(REPORT)), without_times(load_summary(SERIAL)))
        self.assertFalse(os.path.exists(os.path.join(SERIAL, "runs", "wide", "case_c", "images")),
                         "images are removed without --keep-images")

    def test_best_variant_meets_the_issue_bar(self):
        """The best variant's mean |error| on the paper's case C is <= 1 mm, none missed."""
        best = min(VARIANTS, key=lambda v: RECOMPUTED.figures([(v, "case_c")])["error"]["mean_abs_mm"])
        figures = RECOMPUTED.figures([(best, "case_c")])
        self.assertLessEqual(figures["error"]["mean_abs_mm"], 1.0, best)
        self.assertEqual(figures["frames_missed"], 0, best)


def cover_bin(frame):
    if frame["soil"] is None:
        return None
    cover = 1.0 - frame["soil"]
    return next(label for low, high, label in COVER_BINS if low <= cover < high)


class DecisionTest(unittest.TestCase):
    """Paired comparison with the baseline, and the breakdown by condition."""

    def assert_paired(self, reported, expected, where):
        for key, value in expected.items():
            if isinstance(value, float) or value is None:
                self.assertTrue(close(reported[key], value), (where, key, reported[key], value))
            else:
                self.assertEqual(reported[key], value, (where, key))

    def test_each_variant_against_the_baseline(self):
        summary = load_summary(REPORT)
        self.assertEqual(summary["baseline"], BASELINE)
        recordings = sorted(TRUTH_FOLDERS)
        for row in summary["variant_figures"]:
            expected = RECOMPUTED.paired(row["variant"], recordings)
            self.assert_paired(row["against_baseline"], expected, row["variant"])
        # Against itself every difference is 0; the others have frames in all 3 recordings,
        # so an interval with 2 degrees of freedom.
        by_name = {row["variant"]: row["against_baseline"] for row in summary["variant_figures"]}
        self.assertEqual(by_name[BASELINE]["abs_error_difference_mm"], 0.0)
        self.assertEqual(by_name["threshold"]["recordings"], 3)
        self.assertIsNotNone(by_name["threshold"]["abs_error_difference_ci95_low_mm"])

    def test_one_recording_gives_no_interval(self):
        for row in load_summary(REPORT)["recording_figures"]:
            expected = RECOMPUTED.paired(row["variant"], [row["recording"]])
            self.assert_paired(row["against_baseline"], expected, (row["variant"], row["recording"]))
            if row["variant"] != BASELINE:
                self.assertEqual(row["against_baseline"]["verdict"], "too few recordings to tell")

    def expected_conditions(self):
        """(condition, value) -> keep(recording, frame), in the report's order."""
        conditions = []
        for low, high, label in COVER_BINS:
            keep = (lambda label: lambda recording, frame: cover_bin(frame) == label)(label)
            if any(keep(job[1], f) for job, frames in RECOMPUTED.frames.items() for f in frames):
                conditions.append((("residue cover (truth mask)", label), keep))
        keys = sorted({key for tags in TAGS.values() for key in tags})
        for key in keys:
            for value in sorted({tags[key] for tags in TAGS.values() if key in tags}):
                keep = (lambda key, value: lambda recording, frame:
                        TAGS[recording].get(key) == value)(key, value)
                conditions.append((("tag " + key, value), keep))
        return conditions

    def test_figures_by_condition(self):
        reported = load_summary(REPORT)["conditions"]
        expected = self.expected_conditions()
        self.assertEqual([(c["condition"], c["value"]) for c in reported],
                         [name for name, _ in expected])
        self.assertIn(("tag site", "south"), [name for name, _ in expected])
        recordings = sorted(TRUTH_FOLDERS)
        for condition, (name, keep) in zip(reported, expected):
            self.assertEqual([v["variant"] for v in condition["variants"]], VARIANTS)
            for row in condition["variants"]:
                jobs = [(row["variant"], r) for r in recordings]
                SummaryTest.assert_figures(self, row["figures"], RECOMPUTED.figures(jobs, keep),
                                           (name, row["variant"]))
                self.assert_paired(row["against_baseline"],
                                   RECOMPUTED.paired(row["variant"], recordings, keep),
                                   (name, row["variant"]))

    def test_conditions_csv_repeats_the_json(self):
        with open(os.path.join(REPORT, "conditions.csv")) as f:
            rows = list(csv.DictReader(f))
        reported = load_summary(REPORT)["conditions"]
        self.assertEqual(len(rows), len(reported) * len(VARIANTS))
        for row, (condition, variant) in zip(rows, ((c, v) for c in reported for v in c["variants"])):
            self.assertEqual((row["variant"], row["condition"], row["value"]),
                             (variant["variant"], condition["condition"], condition["value"]))
            self.assertEqual(int(row["frames"]), variant["figures"]["frames"])
            self.assertEqual(int(row["frames_missed"]), variant["figures"]["frames_missed"])
            self.assertEqual(row["verdict"], variant["against_baseline"]["verdict"])
            self.assertTrue(close(number(row["abs_error_difference_mm"]),
                                  variant["against_baseline"]["abs_error_difference_mm"]))

    def test_overlays_count_the_residue_called_soil(self):
        """Each variant's overlay says how many pixels of truly residue it called soil."""
        with open(os.path.join(REPORT, "report.html")) as f:
            html = f.read()
        reported = re.findall(r"<figcaption>([^<:]*): (\d+) px residue called soil</figcaption>",
                              html)
        expected = []
        for entry in load_summary(REPORT)["disagreements"]:
            for frame in entry["frames"]:
                images = os.path.join(REPORT, "runs", "%s", entry["recording"], "frames.images")
                name = "%06d.png" % frame["frame_id"]
                truth_file = os.path.join(images % VARIANTS[0], "truth", name)
                if not os.path.exists(truth_file):
                    continue
                truth = cv2.imread(truth_file, cv2.IMREAD_UNCHANGED)
                for variant in VARIANTS:
                    mask = cv2.imread(os.path.join(images % variant, "mask", name),
                                      cv2.IMREAD_UNCHANGED)
                    expected.append((variant, str(int(np.sum((mask == 0) & (truth == 255))))))
        self.assertEqual(reported, expected)
        self.assertTrue(any(count != "0" for _, count in expected))

    def test_recordings_carry_their_tags(self):
        recordings = {r["name"]: r["tags"] for r in load_summary(REPORT)["recordings"]}
        self.assertEqual(recordings, TAGS)


if __name__ == "__main__":
    unittest.main()

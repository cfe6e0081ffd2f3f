"""Tabulates ground-distance errors of a `tilth ab` run over the simulated cases (made by
tools/accuracy.sh, the cases A-E tagged set=paper) like the paper's Table 2: per case the
detected and actual distance and the error, with the error's mean, standard deviation and
95 % confidence interval as `tilth ab` computed them (one way everywhere: Student's t).
Prints Markdown."""
import argparse
import csv
import json
import os
import statistics
import sys

VARIANT = "chain"


def load(report):
    with open(os.path.join(report, "summary.json")) as f:
        summary = json.load(f)
    with open(os.path.join(report, "frames.csv")) as f:
        frames = [row for row in csv.DictReader(f) if row["variant"] == VARIANT]
    return summary, frames


def interval(error):
    if error.get("mean_ci95_low_mm") is None:
        return "-"
    return "[%+.2f, %+.2f]" % (error["mean_ci95_low_mm"], error["mean_ci95_high_mm"])


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--frames", type=int, required=True)
    parser.add_argument("--check-max-error-mm", type=float,
                        help="exit 1 unless every frame of cases A-E is valid and within this "
                             "error, and no frame of 'covered' is valid")
    parser.add_argument("report", help="the folder of the tilth ab run")
    args = parser.parse_args()
    summary, frames = load(args.report)
    problems = []

    print("# Accuracy on the paper's cases\n")
    print("Produced by `bash tools/accuracy.sh %d > docs/accuracy-paper-cases.md`: each case"
          % args.frames)
    print("is simulated (`graphs/simulate.json`, %d frames, seed 1) into an image-folder"
          % args.frames)
    print("recording and replayed through the measurement chain")
    print("(`graphs/measurement-chain.json`, as `graphs/paper.json` runs it) by `tilth ab`,")
    print("whose figures these are. Errors are detected minus actual distance; the 95 %")
    print("interval of the mean error is Student's t, as in the paper's Table 2.\n")
    print("| case | frames | valid | detected (mm) | actual (mm) | error (mm) | std (mm) "
          "| max abs (mm) | 95% CI of error (mm) |")
    print("|---|---|---|---|---|---|---|---|---|")
    for row in summary["recording_figures"]:
        if row["variant"] != VARIANT:
            continue
        name, figures = row["recording"], row["figures"]
        error = figures["error"]
        case_frames = [f for f in frames if f["recording"] == name]
        truths = [float(f["truth_mm"]) for f in case_frames if f["truth_mm"]]
        actual = truths[0] if truths else float("nan")
        distances = [float(f["distance_mm"]) for f in case_frames if f["valid"] == "1"]
        if error["frames_with_error_value"]:
            print("| %s | %d | %d | %.2f | %.2f | %+.2f | %s | %.2f | %s |" % (
                name, figures["frames"], figures["frames_valid"], statistics.fmean(distances),
                actual, error["mean_mm"],
                "%.2f" % error["std_mm"] if error["std_mm"] is not None else "-",
                error["max_abs_mm"], interval(error)))
        else:
            print("| %s | %d | %d | - | %.2f | - | - | - | - |" % (
                name, figures["frames"], figures["frames_valid"], actual))
        if name.startswith("case_"):
            if figures["frames_valid"] != figures["frames"]:
                problems.append("%s: %d of %d frames invalid" % (
                    name, figures["frames"] - figures["frames_valid"], figures["frames"]))
            worst = error["max_abs_mm"] or 0.0
            if args.check_max_error_mm is not None and worst > args.check_max_error_mm:
                problems.append("%s: |error| %.2f mm > %.2f mm" % (name, worst,
                                                                  args.check_max_error_mm))
        if name == "covered" and figures["frames_valid"]:
            problems.append("covered: %d frames reported valid" % figures["frames_valid"])
    together = next((c for c in summary["conditions"]
                     if (c["condition"], c["value"]) == ("tag set", "paper")), None)
    if together:
        error = next(v for v in together["variants"] if v["variant"] == VARIANT)["figures"]["error"]
        if error["frames_with_error_value"]:
            print("\nCases A-E together: mean error %+.2f mm, mean |error| %.2f mm, std %.2f mm, "
                  "max |error| %.2f mm, 95%% CI of the mean %s mm over %d frames." % (
                      error["mean_mm"], error["mean_abs_mm"], error["std_mm"] or 0.0,
                      error["max_abs_mm"], interval(error), error["frames_with_error_value"]))
    print("\nThe paper reports 517.2 mm against 518.0 mm for case A and errors up to 2.2 mm "
          "over cases A-E. `covered` has no visible soil: every frame must be invalid.")
    print("""
## What this shows, and what it does not

- The chain (`segmentation.fusion` and the ground fitted around the tool point,
  docs/measurement.md) is within 0.4 mm of the truth on every frame of the
  paper's cases (mean error -0.02 mm over 100 frames) and reports `covered` invalid on
  every frame, never as a guess. The paper's method, whole (the variant `paper` of
  [accuracy.md](accuracy.md)), is closer on these easy scenes (max |error| 0.13 mm
  against 0.37 over cases A-E there): the median of every soil pixel of the middle half
  averages more noise away than a fit weighted around the tool point, which is what
  holds tilt, ridges, steps, low sun, wet straw and heavy cover, where the paper's
  method is off by 0.7 to 8.5 mm or misses every frame.
- `wet_straw`, the colour threshold's known failure (-0.73 mm: dark, wet straw taken
  for soil), is +0.00 mm: what stands above the soil is residue whatever its colour.
- The simulator's ToF model has range noise of 1 mm at 500 mm, dropouts and mixed
  pixels (the field scenarios of [accuracy.md](accuracy.md) add noise that grows as the
  surface reflects less, and multipath), but no intensity-dependent bias and no
  temperature drift; a real blaze-101 adds those, and
  the tape measure the paper used has its own error. The figures above are therefore
  the chain's own error, not a field accuracy.""")

    if args.check_max_error_mm is not None:
        for problem in problems:
            print("CHECK FAILED: " + problem, file=sys.stderr)
        sys.exit(1 if problems else 0)


if __name__ == "__main__":
    main()

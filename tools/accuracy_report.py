"""Tabulates ground-distance errors from `sinks.csv` files with a truth column, like the
paper's Table 2: per case the detected and actual distance and the error, with the
error's mean, standard deviation and 95 % confidence interval. Prints Markdown."""
import argparse
import csv
import math
import statistics
import sys


def read_case(path):
    rows = list(csv.DictReader(open(path)))
    valid = [r for r in rows if r["valid"] == "1"]
    errors = [float(r["distance_mm"]) - float(r["truth_mm"]) for r in valid]
    return rows, valid, errors


def ci95(values):
    if len(values) < 2:
        return float("nan")
    return 1.96 * statistics.stdev(values) / math.sqrt(len(values))


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--frames", type=int, required=True)
    parser.add_argument("--check-max-error-mm", type=float,
                        help="exit 1 unless every frame of cases A-E is valid and within this "
                             "error, and no frame of 'covered' is valid")
    parser.add_argument("cases", nargs="+", help="NAME=CSV")
    args = parser.parse_args()
    problems = []

    print("# Accuracy on the paper's cases\n")
    print("Produced by `bash tools/accuracy.sh %d > docs/accuracy-paper-cases.md`: each case"
          % args.frames)
    print("is simulated (`graphs/simulate.json`, %d frames, seed 1) into an image-folder"
          % args.frames)
    print("recording and measured by `graphs/paper.json` (the measurement chain,")
    print("`graphs/measurement-chain.json`). Errors are detected minus actual distance.\n")
    print("| case | frames | valid | detected (mm) | actual (mm) | error (mm) | std (mm) "
          "| max abs (mm) | 95% CI of error (mm) |")
    print("|---|---|---|---|---|---|---|---|---|")
    paper_cases = []
    for item in args.cases:
        name, path = item.split("=", 1)
        rows, valid, errors = read_case(path)
        actual = float(rows[0]["truth_mm"]) if rows else float("nan")
        if errors:
            detected = statistics.mean(float(r["distance_mm"]) for r in valid)
            error = statistics.mean(errors)
            std = statistics.stdev(errors) if len(errors) > 1 else 0.0
            half = ci95(errors)
            worst = max(abs(e) for e in errors)
            print("| %s | %d | %d | %.2f | %.2f | %+.2f | %.2f | %.2f | [%+.2f, %+.2f] |" % (
                name, len(rows), len(valid), detected, actual, error, std, worst,
                error - half, error + half))
        else:
            print("| %s | %d | 0 | - | %.2f | - | - | - | - |" % (name, len(rows), actual))
        if name.startswith("case_"):
            paper_cases.append((name, errors))
            if len(valid) != len(rows):
                problems.append("%s: %d of %d frames invalid" % (name, len(rows) - len(valid), len(rows)))
            worst_error = max((abs(e) for e in errors), default=0.0)
            if args.check_max_error_mm is not None and worst_error > args.check_max_error_mm:
                problems.append("%s: |error| %.2f mm > %.2f mm" % (name, worst_error,
                                                                  args.check_max_error_mm))
        if name == "covered" and valid:
            problems.append("covered: %d frames reported valid" % len(valid))
    all_errors = [e for _, errors in paper_cases for e in errors]
    if all_errors:
        print("\nCases A-E together: mean error %+.2f mm, mean |error| %.2f mm, std %.2f mm, "
              "max |error| %.2f mm, 95%% CI of the mean [%+.2f, %+.2f] mm over %d frames." % (
                  statistics.mean(all_errors), statistics.mean(abs(e) for e in all_errors),
                  statistics.stdev(all_errors), max(abs(e) for e in all_errors),
                  statistics.mean(all_errors) - ci95(all_errors),
                  statistics.mean(all_errors) + ci95(all_errors), len(all_errors)))
    print("\nThe paper reports 517.2 mm against 518.0 mm for case A and errors up to 2.2 mm "
          "over cases A-E. `covered` has no visible soil: every frame must be invalid.")
    print("""
## What this shows, and what it does not

- The chain (`segmentation.fusion` and the ground fitted around the tool point,
  docs/measurement.md) is within 0.3 mm of the truth on every frame of the
  paper's cases and reports `covered` invalid on every frame, never as a guess. The
  paper's method (the variant `paper`) was closer on these easy scenes (mean error
  −0.03 mm, max 0.15 mm): the median of every soil pixel of the middle half averages
  more noise away than a fit weighted within about 20 mm of the tool point, which costs
  about 0.1 mm here and is what holds tilt, ridges and heavy cover
  ([accuracy.md](accuracy.md)).
- `wet_straw`, the colour threshold's known failure (−0.73 mm: dark, wet straw taken for
  soil), is −0.07 mm: what stands above the soil is residue whatever its colour.
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

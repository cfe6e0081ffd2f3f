#!/usr/bin/env python3
"""The learned segmenters against the colour rules on simulated recordings, leave one
recording out (docs/segmentation-variants.md, "Learned against the colour rules").
self_trained alone sees the held-out recording: it learns online from the scene it
segments, which is what it is for.

Each preset is simulated (`tilth simulate`) into an image-folder recording. For each
recording, every learned model is trained by `tilth train-segmenter` on all the other
recordings, then `tilth ab` runs the recording through the measurement chain once per
segmenter: the three colour rules, `segmentation.self_trained` (which learns online, from
the recording itself), and the held-out models, the pixel classifier and the CNN, each
trained on the masks and on labels from depth. Every segmenter is scored the same way:
its mask undilated and not despeckled (the decision itself), over the region the chain
segments (`middle_half`), against the truth's soil and residue pixels, a pixel called
unknown counting as not residue (sinks.evaluation). The table is residue IoU per
recording, and pooled over all pixels. Two columns, classifier_field and cnn_field, are
trained on other passes over the same fields (each preset simulated again with
--field-seed), by their labels from depth: a field's own unlabelled recordings, as
`tilth train-segmenter --labels depth` is for. They never see the held-out recording.

    python3 tools/compare_segmenters.py --recordings /tmp/segmenters > table.md

TILTH=path/to/tilth uses another build. --recordings DIR keeps the recordings and the
models there and reuses them on the next run. --cnn-epochs and --cnn-steps set the CNN's
training (default 12 epochs of 15 batches, as tests/tools/test_train_segmenter_cnn.py).
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile

SOURCE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PRESETS = ["case_c", "case_e", "wet_straw", "shadows", "low_sun", "heavy_cover", "field"]

# name, what it is, the chain's segment node set to it.
RULES = [
    ("color_threshold", "the paper's colour threshold", {"segment.type": "segmentation.color_threshold"}),
    ("color_index", "colour index, Otsu threshold", {"segment.type": "segmentation.color_index"}),
    ("lab_clusters", "two clusters in Lab", {"segment.type": "segmentation.lab_clusters"}),
    # Trained on the graph's thread, so that the run repeats; on its first frame, then
    # every 10th (its default).
    ("self_trained", "a forest learnt online from the recording's depth labels",
     {"segment.type": "segmentation.self_trained", "segment.training": "inline"}),
]
# name, what it is, train-segmenter options, the stage, its model file's extension, and
# what it is trained on: the other recordings ("others") or the fields' other passes
# ("field", by their depth labels; one model for every held-out recording).
LEARNED = [
    ("classifier", "pixel classifier (texture, forest) trained on the masks", [],
     "segmentation.pixel_classifier", ".yml.gz", "others"),
    ("classifier_depth", "the same trained on labels from depth", ["--labels", "depth"],
     "segmentation.pixel_classifier", ".yml.gz", "others"),
    ("classifier_field", "the same trained on labels from depth of other passes over the "
     "same fields: a field's unlabelled recordings", ["--labels", "depth"],
     "segmentation.pixel_classifier", ".yml.gz", "field"),
    ("cnn", "the U-Net trained on the masks", ["--model", "cnn"], "segmentation.cnn", ".onnx",
     "others"),
    ("cnn_depth", "the same trained on labels from depth", ["--model", "cnn", "--labels", "depth"],
     "segmentation.cnn", ".onnx", "others"),
    ("cnn_field", "the U-Net trained on labels from depth of other passes over the same "
     "fields", ["--model", "cnn", "--labels", "depth"], "segmentation.cnn", ".onnx", "field"),
]
# The same scoring for every segmenter.
SCORED = {"segment.dilation_px": 0, "segment.speckle_px": 0, "segment.roi": "middle_half"}


def run(command, log):
    log.write("$ " + " ".join(command) + "\n")
    log.flush()
    result = subprocess.run(command, stdout=log, stderr=subprocess.STDOUT, timeout=3600)
    if result.returncode != 0:
        sys.exit("failed (%d): %s; see %s" % (result.returncode, " ".join(command), log.name))


def simulate(tilth, folder, preset, seed, args, log):
    path = os.path.join(folder, preset)
    if not os.path.isdir(path):
        run([tilth, "simulate", path, "--preset", preset, "--seed", str(seed), "--frames",
             str(args.frames)], log)
    return path


def train(tilth, folder, held, recordings, passes, learned, args, log):
    name, _, options, _, extension, trained_on = learned
    if trained_on == "field":
        model = os.path.join(folder, "models", "%s-seed%d%s" % (name, args.field_seed, extension))
        trained = passes
    else:
        model = os.path.join(folder, "models", "%s-without-%s%s" % (
            name, os.path.basename(held), extension))
        trained = [r for r in recordings if r != held]
    if not os.path.exists(model):
        command = [tilth, "train-segmenter", *trained, "--test", held, "--out", model, *options]
        if "cnn" in options:
            command += ["--epochs", str(args.cnn_epochs), "--steps", str(args.cnn_steps)]
        run(command, log)
    return model


def variant_options(name, settings):
    options = []
    for key, value in {**settings, **SCORED}.items():
        options += ["--variant", "%s:%s=%s" % (name, key, value)]
    return options


def mask_counts(summary):
    counts = {}
    for variant in summary["variant_figures"]:
        mask = variant["figures"]["mask"]
        counts[variant["variant"]] = (mask["px_residue_called_residue"],
                                      mask["px_soil_called_residue"],
                                      mask["px_residue_called_soil_or_unknown"])
    return counts


def iou(tp, fp, fn):
    return tp / (tp + fp + fn) if tp + fp + fn else float("nan")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--recordings", help="keep recordings and models here")
    parser.add_argument("--presets", nargs="+", default=PRESETS)
    # Static presets re-noise one scene per frame: more frames add little.
    parser.add_argument("--frames", type=int, default=3)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--field-seed", type=int, default=2,
                        help="the fields' other passes, which the _field models train on")
    parser.add_argument("--only", nargs="+", help="these segmenters alone")
    parser.add_argument("--cnn-epochs", type=int, default=12)
    parser.add_argument("--cnn-steps", type=int, default=15)
    args = parser.parse_args()
    tilth = os.environ.get("TILTH", os.path.join(SOURCE, "build", "bin", "tilth"))
    folder = args.recordings or tempfile.mkdtemp(prefix="tilth-segmenters-")
    os.makedirs(os.path.join(folder, "models"), exist_ok=True)
    rules = [r for r in RULES if not args.only or r[0] in args.only]
    learned_ones = [l for l in LEARNED if not args.only or l[0] in args.only]
    names = [r[0] for r in rules] + [l[0] for l in learned_ones]
    table = {}
    with open(os.path.join(folder, "log.txt"), "a") as log:
        recordings = [simulate(tilth, folder, preset, args.seed, args, log)
                      for preset in args.presets]
        passes = []
        if any(learned[5] == "field" for learned in learned_ones):
            passes = [simulate(tilth, os.path.join(folder, "seed%d" % args.field_seed), preset,
                               args.field_seed, args, log) for preset in args.presets]
        for held in recordings:
            variants = []
            for name, _, settings in rules:
                variants += variant_options(name, settings)
            for learned in learned_ones:
                model = train(tilth, folder, held, recordings, passes, learned, args, log)
                variants += variant_options(learned[0], {"segment.type": learned[3],
                                                         "segment.model": model})
            out = os.path.join(folder, "ab", os.path.basename(held))
            shutil.rmtree(out, ignore_errors=True)
            run([tilth, "ab", held, "--out", out, *variants], log)
            with open(os.path.join(out, "summary.json")) as f:
                table[os.path.basename(held)] = mask_counts(json.load(f))
            print("%s done" % os.path.basename(held), file=sys.stderr)

    print("| recording | " + " | ".join("`%s`" % n for n in names) + " |")
    print("|---|" + "---|" * len(names))
    pooled = {n: [0, 0, 0] for n in names}
    for recording, counts in table.items():
        cells = []
        for n in names:
            cells.append("%.2f" % iou(*counts[n]))
            pooled[n] = [a + b for a, b in zip(pooled[n], counts[n])]
        print("| `%s` | %s |" % (recording, " | ".join(cells)))
    print("| all pixels | %s |" % " | ".join("**%.2f**" % iou(*pooled[n]) for n in names))
    print()
    for name, what, *_ in rules + learned_ones:
        print("- `%s`: %s" % (name, what))


if __name__ == "__main__":
    main()

"""segmentation.cnn runs the network as tools/train_segmenter/train_cnn.py trained it: a
small U-Net (seeded, briefly trained so that its output is not flat) exported to ONNX with
its sidecar; the stage's preparation and OpenCV's dnn (cnn_probe) give the probabilities
PyTorch gives on the same image through train_cnn.prepare, and the stage's mask is those
probabilities resized bilinearly and thresholded. The models the stage refuses are
refused with the file, the place in it and what was expected.
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

SOURCE = os.environ["TILTH_SOURCE_DIR"]
sys.path.insert(0, os.path.join(SOURCE, "tests", "support"))
sys.path.insert(0, os.path.join(SOURCE, "tools", "train_segmenter"))
from processes import run_bounded  # noqa: E402

import numpy as np  # noqa: E402
import torch  # noqa: E402
import torch.nn.functional as F  # noqa: E402
from PIL import Image  # noqa: E402

import train_cnn  # noqa: E402

PROBE = os.environ["CNN_PROBE"]
WIDTH, HEIGHT = 32, 24
# Both sides compute in float32 with the same operations in other orders (OpenCV's
# convolutions are blocked and vectorised, PyTorch's go through oneDNN): through eight
# convolution layers their sums differ in the last bits, 1e-6 in a probability; 1e-4 is
# a hundred times that, and far below the 0.5 % of a probability a change of one input
# value makes (measured: 6e-8 here).
TOLERANCE = 1e-4


def textured_image(height, width, seed):
    """Bright straw-like stripes on darker soil with noise: every value of 0..255 used."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:height, 0:width]
    straw = (np.sin(x * 0.21 + y * 0.07) > 0.4)[..., None]
    rgb = np.where(straw, [220, 190, 120], [110, 80, 55]) + rng.normal(0, 20, (height, width, 3))
    return np.clip(rgb, 0, 255).astype(np.uint8)


class CnnAgreementTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.folder = tempfile.mkdtemp(prefix="cnn-agreement-")
        frames = os.path.join(cls.folder, "frames")
        os.mkdir(frames)
        # Two training frames, labelled by the stripes, so that the trained network's
        # output varies over the image and crosses the threshold.
        for i in range(2):
            rgb = textured_image(192, 256, i)
            labels = np.where(rgb[..., 0] > 165, 255, 0).astype(np.uint8)
            Image.fromarray(rgb).save(os.path.join(frames, "%06d.color.png" % i))
            Image.fromarray(labels).save(os.path.join(frames, "%06d.labels.png" % i))
        cls.model = os.path.join(cls.folder, "tiny.onnx")
        args = train_cnn.arguments(["--frames", frames, "--out", cls.model, "--width", str(WIDTH),
                                    "--height", str(HEIGHT), "--channels", "4,8,8",
                                    "--epochs", "3", "--steps", "4", "--batch", "2",
                                    "--seed", "5"])
        torch.set_num_threads(1)
        cls.net, mean, std, _, _ = train_cnn.train(train_cnn.read_frames([frames]), args,
                                                   lambda line: None)
        train_cnn.export(cls.net, args, mean, std, "agreement test")
        with open(os.path.join(cls.folder, "tiny.json")) as f:
            cls.sidecar = json.load(f)
        # An image four times the network's input: the area averaging is exact on both sides.
        cls.rgb = textured_image(4 * HEIGHT, 4 * WIDTH, 7)
        cls.image = os.path.join(cls.folder, "image.png")
        Image.fromarray(cls.rgb).save(cls.image)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.folder)

    def torch_probabilities(self):
        prepared = train_cnn.prepare(self.rgb, (WIDTH, HEIGHT), self.sidecar["input"]["mean"],
                                     self.sidecar["input"]["std"])
        with torch.no_grad():
            return self.net(prepared)

    def probe(self, mode, model, out):
        return run_bounded([PROBE, mode, model, self.image, out], self.folder, seconds=60)

    def test_opencv_gives_pytorchs_probabilities(self):
        out = os.path.join(self.folder, "probabilities.f32")
        result = self.probe("probabilities", self.model, out)
        self.assertEqual(result.returncode, 0, result.stderr)
        opencv = np.fromfile(out, dtype=np.float32).reshape(HEIGHT, WIDTH)
        pytorch = self.torch_probabilities()[0, 0].numpy()
        self.assertGreater(pytorch.max() - pytorch.min(), 0.2, "a network with a flat output")
        self.assertLess(np.abs(opencv - pytorch).max(), TOLERANCE)

    def test_stage_mask_is_the_thresholded_probability(self):
        out = os.path.join(self.folder, "mask.png")
        result = self.probe("stage", self.model, out)
        self.assertEqual(result.returncode, 0, result.stderr)
        mask = np.asarray(Image.open(out))
        probability = F.interpolate(self.torch_probabilities(), size=self.rgb.shape[:2],
                                    mode="bilinear", align_corners=False)[0, 0].numpy()
        threshold = self.sidecar["output"]["threshold"]
        # Pixels within TOLERANCE of the threshold may go either way.
        clear = np.abs(probability - threshold) > TOLERANCE
        expected = np.where(probability > threshold, 255, 0)
        self.assertGreater(clear.mean(), 0.99)
        self.assertTrue(0.05 < (expected == 255).mean() < 0.95, "one class everywhere")
        np.testing.assert_array_equal(mask[clear], expected[clear])

    def refused(self, model):
        result = self.probe("stage", model, os.path.join(self.folder, "refused.png"))
        self.assertEqual(result.returncode, 1, result.stdout + result.stderr)
        return result.stderr

    def copy_model(self, name, sidecar=None, onnx_bytes=None):
        onnx = os.path.join(self.folder, name + ".onnx")
        if onnx_bytes is None:
            shutil.copy(self.model, onnx)
        else:
            with open(onnx, "wb") as f:
                f.write(onnx_bytes)
        with open(os.path.join(self.folder, name + ".json"), "w") as f:
            json.dump(self.sidecar if sidecar is None else sidecar, f)
        return onnx

    def test_missing_model(self):
        missing = os.path.join(self.folder, "missing.onnx")
        self.assertIn("model '%s': no such file" % missing, self.refused(missing))

    def test_broken_onnx(self):
        onnx = self.copy_model("broken", onnx_bytes=b"\x08\x07\x3a\xff\xff\x03not a model")
        self.assertIn("ONNX model '%s': damaged" % onnx, self.refused(onnx))

    def test_sidecar_of_another_format(self):
        sidecar = dict(self.sidecar, format="tilth-pixel-classifier/2")
        onnx = self.copy_model("other", sidecar)
        self.assertIn("model sidecar '%s' at /format: expected \"tilth-cnn-segmenter/1\", got "
                      "\"tilth-pixel-classifier/2\"" % onnx.replace(".onnx", ".json"),
                      self.refused(onnx))

    def test_missing_sidecar_value(self):
        sidecar = json.loads(json.dumps(self.sidecar))
        del sidecar["input"]["std"]
        onnx = self.copy_model("nostd", sidecar)
        self.assertIn("at /input/std: missing (expected 3 numbers, R G B)", self.refused(onnx))

    def test_input_size_disagreeing_with_the_sidecar(self):
        sidecar = json.loads(json.dumps(self.sidecar))
        sidecar["input"]["width"] = WIDTH + 4
        onnx = self.copy_model("wider", sidecar)
        self.assertIn("its input is 1x3x%dx%d (expected 1x3x%dx%d, the size its sidecar"
                      % (HEIGHT, WIDTH, HEIGHT, WIDTH + 4), self.refused(onnx))


if __name__ == "__main__":
    unittest.main()

"""An independent reader of an image-folder recording written by `tilth run`.

The test writes a recording with its own code, copies it with the graph
recording.image_folder (host_time: recorded) -> recording.image_folder_writer, and
checks the copy against docs/formats/recording-folder.md and the input: recording.json, the
frames.csv columns, each PNG's bit depth and colour type (read from its header), and
every pixel, decoded once by the small PNG decoder below (no OpenCV involved) and once
by OpenCV; and Tilth's extension host_timestamps.csv: the input's host times, or without
them the times the copy was made."""
import csv
import json
import os
import struct
import subprocess
import sys
import tempfile
import time
import unittest
import zlib

import cv2
import numpy as np

SUPPORT = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "support")
sys.path.insert(0, SUPPORT)
from rigs import paper_rig_path  # noqa: E402

TILTH = os.environ["TILTH_BIN"]

HEADER = ["index", "depth_timestamp_ns", "color_timestamp_ns", "depth", "color", "mask",
          "ground_truth_mm"]
HOST_HEADER = ["index", "host_timestamp_ns"]
PNG_GRAY, PNG_RGB = 0, 2


def read_png(path):
    """(bit depth, colour type, pixels) of a non-interlaced gray or RGB PNG; pixels as
    stored: RGB order, 16-bit samples big-endian."""
    with open(path, "rb") as f:
        data = f.read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", path
    position, idat, header = 8, b"", None
    while position < len(data):
        length, kind = struct.unpack(">I4s", data[position:position + 8])
        body = data[position + 8:position + 8 + length]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        position += 12 + length
    width, height, bit_depth, color_type, _, _, interlace = header
    assert interlace == 0, path
    channels = {PNG_GRAY: 1, PNG_RGB: 3}[color_type]
    step = channels * bit_depth // 8  # bytes per pixel
    stride = width * step
    raw = zlib.decompress(idat)
    rows, previous = [], bytearray(stride)
    for y in range(height):
        kind = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for x in range(stride):
            left = line[x - step] if x >= step else 0
            up = previous[x]
            up_left = previous[x - step] if x >= step else 0
            if kind == 1:
                line[x] = (line[x] + left) & 0xFF
            elif kind == 2:
                line[x] = (line[x] + up) & 0xFF
            elif kind == 3:
                line[x] = (line[x] + (left + up) // 2) & 0xFF
            elif kind == 4:
                p = left + up - up_left
                pa, pb, pc = abs(p - left), abs(p - up), abs(p - up_left)
                predictor = left if pa <= pb and pa <= pc else up if pb <= pc else up_left
                line[x] = (line[x] + predictor) & 0xFF
        rows.append(bytes(line))
        previous = line
    dtype = ">u2" if bit_depth == 16 else "u1"
    pixels = np.frombuffer(b"".join(rows), dtype=dtype).reshape(height, width, channels)
    return bit_depth, color_type, pixels.squeeze(axis=2) if channels == 1 else pixels


def small_calibration():
    with open(paper_rig_path()) as f:
        calibration = json.load(f)
    # The principal points move with the sizes: a calibration's must lie inside its image.
    calibration["depth_camera"].update(width=20, height=16, cx=9.5, cy=7.5)
    calibration["color_camera"].update(width=28, height=18, cx=13.5, cy=8.5)
    return calibration


def make_frames(count, color_channels, calibration):
    random = np.random.default_rng(7)
    depth_shape = (calibration["depth_camera"]["height"], calibration["depth_camera"]["width"])
    color_shape = (calibration["color_camera"]["height"], calibration["color_camera"]["width"])
    if color_channels == 3:
        color_shape += (3,)
    frames = []
    for i in range(count):
        depth = random.integers(0, 65536, depth_shape, dtype=np.uint16)
        depth[0, 0], depth[0, 1] = 0, 65535
        frame = {
            "index": 10 + 2 * i,
            "depth_ns": 5_000_000_000 + i * 33_333_333,
            "color_ns": 5_000_000_000 + i * 33_333_333 + 1_250_000,
            # CLOCK_REALTIME in November 2025, with jitter.
            "host_ns": 1_763_800_000_000_000_000 + i * 33_400_000 + (i % 2) * 250_000,
            "depth": depth,
            "color": random.integers(0, 256, color_shape, dtype=np.uint8),
            "mask": None,
            "truth": None,
        }
        if i % 2 == 1:
            frame["mask"] = random.choice(np.array([0, 128, 255], dtype=np.uint8), depth_shape)
            frame["truth"] = 518.25 + i
        frames.append(frame)
    return frames


def write_input_recording(folder, frames, color_format, calibration, host_timestamps=False):
    for sub in ("depth", "color", "mask", "calib"):
        os.makedirs(os.path.join(folder, sub), exist_ok=True)
    with open(os.path.join(folder, "calib", "rig.json"), "w") as f:
        json.dump(calibration, f)
    lines = [",".join(HEADER)]
    for frame in frames:
        name = "%06d.png" % frame["index"]
        assert cv2.imwrite(os.path.join(folder, "depth", name), frame["depth"])
        assert cv2.imwrite(os.path.join(folder, "color", name), frame["color"])
        mask = ""
        if frame["mask"] is not None:
            mask = "mask/" + name
            assert cv2.imwrite(os.path.join(folder, mask), frame["mask"])
        truth = "" if frame["truth"] is None else repr(frame["truth"])
        lines.append("%d,%d,%d,depth/%s,color/%s,%s,%s" % (
            frame["index"], frame["depth_ns"], frame["color_ns"], name, name, mask, truth))
    with open(os.path.join(folder, "frames.csv"), "w") as f:
        f.write("\n".join(lines) + "\n")
    if host_timestamps:
        with open(os.path.join(folder, "host_timestamps.csv"), "w") as f:
            f.write(",".join(HOST_HEADER) + "\n")
            f.writelines("%d,%d\n" % (frame["index"], frame["host_ns"]) for frame in frames)
    with open(os.path.join(folder, "recording.json"), "w") as f:
        json.dump({"format": "tilth-image-folder/1", "calibration": "calib/rig.json",
                   "color_format": color_format, "description": "made by check_folder.py"}, f)


def copy_with_tilth(source, target, calibration_file, tmp):
    graph = {
        "nodes": {
            "replay": {"type": "recording.image_folder",
                       "params": {"path": source, "host_time": "recorded"}},
            "write": {"type": "recording.image_folder_writer",
                      "params": {"path": target, "calibration": calibration_file,
                                 "description": "written by tilth run"}},
        },
        "edges": [["replay.raw", "write.raw"], ["replay.color", "write.color"],
                  ["replay.truth", "write.truth"]],
    }
    path = os.path.join(tmp, "copy.json")
    with open(path, "w") as f:
        json.dump(graph, f)
    return subprocess.run([TILTH, "run", path, "--quiet"], capture_output=True, text=True,
                          timeout=120)


class WrittenFolder(unittest.TestCase):
    def check_copy(self, color_format, color_channels, host_timestamps):
        calibration = small_calibration()
        frames = make_frames(5, color_channels, calibration)
        with tempfile.TemporaryDirectory() as tmp:
            source, target = os.path.join(tmp, "in"), os.path.join(tmp, "out")
            write_input_recording(source, frames, color_format, calibration, host_timestamps)
            start_ns = time.time_ns()
            result = copy_with_tilth(source, target, os.path.join(source, "calib", "rig.json"),
                                     tmp)
            end_ns = time.time_ns()
            self.assertEqual(result.returncode, 0, result.stderr)

            with open(os.path.join(target, "host_timestamps.csv"), newline="") as f:
                host_rows = list(csv.reader(f))
            self.assertEqual(host_rows[0], HOST_HEADER)
            self.assertEqual([int(row[0]) for row in host_rows[1:]],
                             [frame["index"] for frame in frames])
            host_ns = [int(row[1]) for row in host_rows[1:]]
            if host_timestamps:
                self.assertEqual(host_ns, [frame["host_ns"] for frame in frames])
            else:  # stamped as they were replayed
                self.assertEqual(host_ns, sorted(host_ns))
                self.assertGreaterEqual(host_ns[0], start_ns)
                self.assertLessEqual(host_ns[-1], end_ns)

            with open(os.path.join(target, "recording.json")) as f:
                recording = json.load(f)
            self.assertEqual(recording, {"format": "tilth-image-folder/1",
                                         "calibration": "rig.calib.json",
                                         "color_format": color_format,
                                         "description": "written by tilth run"})
            with open(os.path.join(target, "rig.calib.json")) as f:
                self.assertEqual(json.load(f), calibration)

            with open(os.path.join(target, "frames.csv"), newline="") as f:
                rows = list(csv.reader(f))
            self.assertEqual(rows[0], HEADER)
            self.assertEqual(len(rows), 1 + len(frames))
            for frame, row in zip(frames, rows[1:]):
                with self.subTest(index=frame["index"]):
                    self.check_frame(target, frame, dict(zip(HEADER, row)), color_channels)

    def check_frame(self, target, frame, row, color_channels):
        name = "%06d.png" % frame["index"]
        self.assertEqual(int(row["index"]), frame["index"])
        self.assertEqual(int(row["depth_timestamp_ns"]), frame["depth_ns"])
        self.assertEqual(int(row["color_timestamp_ns"]), frame["color_ns"])
        self.assertEqual(row["depth"], "depth/" + name)
        self.assertEqual(row["color"], "color/" + name)

        bits, kind, depth = read_png(os.path.join(target, row["depth"]))
        self.assertEqual((bits, kind), (16, PNG_GRAY))
        np.testing.assert_array_equal(depth.astype(np.uint16), frame["depth"])
        opencv_depth = cv2.imread(os.path.join(target, row["depth"]), cv2.IMREAD_UNCHANGED)
        self.assertEqual(opencv_depth.dtype, np.uint16)
        np.testing.assert_array_equal(opencv_depth, frame["depth"])

        bits, kind, color = read_png(os.path.join(target, row["color"]))
        if color_channels == 3:
            self.assertEqual((bits, kind), (8, PNG_RGB))
            np.testing.assert_array_equal(color, frame["color"][:, :, ::-1])  # BGR stored as RGB
        else:
            self.assertEqual((bits, kind), (8, PNG_GRAY))
            np.testing.assert_array_equal(color, frame["color"])
        np.testing.assert_array_equal(
            cv2.imread(os.path.join(target, row["color"]), cv2.IMREAD_UNCHANGED), frame["color"])

        if frame["mask"] is None:
            self.assertEqual(row["mask"], "")
            self.assertFalse(os.path.exists(os.path.join(target, "mask", name)))
        else:
            self.assertEqual(row["mask"], "mask/" + name)
            bits, kind, mask = read_png(os.path.join(target, row["mask"]))
            self.assertEqual((bits, kind), (8, PNG_GRAY))
            np.testing.assert_array_equal(mask, frame["mask"])

        if frame["truth"] is None:
            self.assertEqual(row["ground_truth_mm"], "")
        else:
            self.assertEqual(float(row["ground_truth_mm"]), frame["truth"])
            self.assertGreaterEqual(len(row["ground_truth_mm"].split(".")[1]), 2)

    def test_bgr8_with_host_timestamps(self):
        self.check_copy("bgr8", 3, host_timestamps=True)

    def test_bayer_without_host_timestamps(self):
        self.check_copy("bayer_bggr8", 1, host_timestamps=False)


if __name__ == "__main__":
    unittest.main()

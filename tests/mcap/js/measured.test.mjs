// What the chain measured, recorded beside the frames: synthetic.scene on the field rig
// (its colour camera rotated and offset) -> the measurement chain -> mcap.writer with the
// chain's distance, mask and registered colour, and a csv sink of the same distances. An
// independent reader (readers.mjs: Foxglove's @mcap/core and its ROS 2 decoder) checks
// the channels' schemas, each frame's /tilth/distance against the csv sink, the mask's and
// registered colour's images, the cameras' calibrations against the rig file, and the
// colour camera's pose in the depth camera's frame against the rig's depth_to_color.
import assert from "node:assert/strict";
import { execFileSync } from "node:child_process";
import fs from "node:fs";
import os from "node:os";
import path from "node:path";
import { test } from "node:test";

import { decoderFor, messagesOn, openMcap, stampNs } from "./readers.mjs";
import { fieldRigPath } from "../../support/rigs.mjs";

const TILTH = process.env.TILTH_BIN;
const SOURCE = process.env.TILTH_SOURCE_DIR;
const RIG = JSON.parse(fs.readFileSync(fieldRigPath()));
const FRAMES = 3;

function record() {
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), "tilth-mcap-measured-"));
  const graph = {
    include: [{ file: path.join(SOURCE, "graphs", "measurement-chain.json"), as: "chain",
                variables: { calibration: fieldRigPath() } }],
    nodes: {
      scene: { type: "synthetic.scene",
               params: { calibration: fieldRigPath(), preset: "case_c", frames: FRAMES } },
      mcap: { type: "mcap.writer",
              params: { path: path.join(dir, "measured.mcap"), calibration: fieldRigPath(),
                        when_behind: "wait" } },
      csv: { type: "sinks.csv", params: { path: path.join(dir, "distances.csv") } },
    },
    edges: [
      ["scene.raw", "chain/project.raw"], ["scene.color", "chain/register.color"],
      ["scene.raw", "mcap.raw"], ["scene.color", "mcap.color"], ["scene.truth", "mcap.truth"],
      ["chain/estimate.distance", "mcap.distance"], ["chain/segment.mask", "mcap.mask"],
      ["chain/register.color", "mcap.registered"], ["chain/estimate.distance", "csv.distance"],
    ],
    runtime: { on_error: "stop" },
  };
  fs.writeFileSync(path.join(dir, "graph.json"), JSON.stringify(graph));
  execFileSync(TILTH, ["run", path.join(dir, "graph.json"), "--quiet"], { stdio: "inherit" });
  return dir;
}

const dir = record();
const file = path.join(dir, "measured.mcap");
const csvLines = fs.readFileSync(path.join(dir, "distances.csv"), "utf8").trim().split("\n");
const header = csvLines[0].split(",");
const csvRows = csvLines.slice(1).map((line) => Object.fromEntries(
  line.split(",").map((value, i) => [header[i], value])));

const JSON_SCHEMAS = {
  "/truth": "tilth.GroundTruth", "/tilth/distance": "tilth.GroundDistance",
  "/tof/calibration": "foxglove.CameraCalibration",
  "/color/calibration": "foxglove.CameraCalibration", "/tf": "foxglove.FrameTransform",
};

test("what the chain measured has its channels, in schemas Foxglove reads", async () => {
  const reader = await openMcap(file);
  const counts = {};
  for (const channel of reader.channelsById.values()) {
    const schema = reader.schemasById.get(channel.schemaId);
    const json = JSON_SCHEMAS[channel.topic];
    assert.equal(schema.name, json ?? "foxglove_msgs/msg/RawImage", channel.topic);
    assert.equal(channel.messageEncoding, json ? "json" : "cdr", channel.topic);
    decoderFor(reader, channel.id);  // the schema parses
    counts[channel.topic] = Number(reader.statistics.channelMessageCounts.get(channel.id));
  }
  assert.deepEqual(counts, {
    "/tof/raw": FRAMES, "/color/image": FRAMES, "/truth": FRAMES, "/truth/mask": FRAMES,
    "/tilth/distance": FRAMES, "/tilth/mask": FRAMES, "/tilth/registered_color": FRAMES,
    "/tof/calibration": 1, "/color/calibration": 1, "/tf": 1,
  });
});

test("each frame's distance is the one the chain handed on", async () => {
  const reader = await openMcap(file);
  const distances = await messagesOn(reader, "/tilth/distance");
  const raw = await messagesOn(reader, "/tof/raw");
  const decode = decoderFor(reader, distances[0].channelId);
  const decodeImage = decoderFor(reader, raw[0].channelId);
  assert.equal(distances.length, csvRows.length);
  distances.forEach((message, i) => {
    const distance = decode(message);
    const row = csvRows[i];
    assert.equal(message.sequence, Number(row.index));
    assert.equal(message.logTime, raw[i].logTime);
    assert.equal(stampNs(distance.timestamp), stampNs(decodeImage(raw[i]).timestamp));
    assert.equal(distance.valid, row.valid === "1");
    assert.ok(distance.valid, "case C has soil in view: every frame valid");
    // The csv sink writes 3 decimals.
    assert.ok(Math.abs(distance.distance_mm - Number(row.distance_mm)) <= 0.0005,
              `${distance.distance_mm} against ${row.distance_mm}`);
    assert.equal(distance.invalid_cause, "none");
    assert.ok(distance.soil_fraction > 0 && distance.soil_fraction <= 1);
  });
});

test("the mask and the registered colour are images on the depth grid", async () => {
  const reader = await openMcap(file);
  const width = RIG.depth_camera.width, height = RIG.depth_camera.height;
  const [mask] = await messagesOn(reader, "/tilth/mask");
  const image = decoderFor(reader, mask.channelId)(mask);
  assert.deepEqual([image.encoding, image.frame_id, image.width, image.height],
                   ["mono8", "tof", width, height]);
  const values = new Set(image.data);
  assert.deepEqual([...values].sort((a, b) => a - b), [0, 128, 255]);
  const [registered] = await messagesOn(reader, "/tilth/registered_color");
  const colour = decoderFor(reader, registered.channelId)(registered);
  assert.deepEqual([colour.encoding, colour.frame_id, colour.width, colour.height, colour.step],
                   ["bgr8", "tof", width, height, 3 * width]);
  assert.ok(colour.data.some((byte) => byte > 0), "the registered colour is not all black");
});

test("each camera's calibration is the rig file's", async () => {
  const reader = await openMcap(file);
  for (const [topic, camera, frameId] of [["/tof/calibration", RIG.depth_camera, "tof"],
                                          ["/color/calibration", RIG.color_camera, "color"]]) {
    const [message] = await messagesOn(reader, topic);
    const calibration = decoderFor(reader, message.channelId)(message);
    assert.equal(calibration.frame_id, frameId);
    assert.deepEqual([calibration.width, calibration.height], [camera.width, camera.height]);
    assert.equal(calibration.distortion_model, "plumb_bob");
    assert.deepEqual(calibration.D, camera.distortion);
    assert.deepEqual(calibration.K, [camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1]);
    assert.deepEqual(calibration.P.slice(0, 3), [camera.fx, 0, camera.cx]);
  }
});

test("the colour camera's pose in the depth camera's frame inverts depth_to_color", async () => {
  const reader = await openMcap(file);
  const [message] = await messagesOn(reader, "/tf");
  const pose = decoderFor(reader, message.channelId)(message);
  assert.equal(pose.parent_frame_id, "tof");
  assert.equal(pose.child_frame_id, "color");
  const { x, y, z, w } = pose.rotation;
  assert.ok(Math.abs(x * x + y * y + z * z + w * w - 1) < 1e-12, "a unit quaternion");
  // The quaternion's matrix: the colour frame's axes in the depth frame, R transposed.
  const m = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
             [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
             [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]];
  const R = RIG.depth_to_color.R, T = RIG.depth_to_color.T_mm;
  for (let i = 0; i < 3; i++) {
    for (let j = 0; j < 3; j++) assert.ok(Math.abs(m[i][j] - R[j][i]) < 1e-7, `R[${j}][${i}]`);
  }
  // The colour camera's centre in the depth frame, -R^T T, in metres.
  const centre = [0, 1, 2].map((i) => -(R[0][i] * T[0] + R[1][i] * T[1] + R[2][i] * T[2]) / 1000);
  const t = pose.translation;
  [t.x, t.y, t.z].forEach((value, i) => assert.ok(Math.abs(value - centre[i]) < 1e-12, `t[${i}]`));
  assert.ok(Math.abs(t.x + 0.052) < 1e-3, "about 52 mm to the left of the ToF camera");
});

// An independent reader of an MCAP file written by `tilth run` (readers.mjs: Foxglove's
// @mcap/core and its ROS 2 message decoder) reads a recording of synthetic.scene made by
// mcap.writer, and checks it against the image-folder recording that
// recording.image_folder_writer made of the same frames in the same graph: channel
// names and schemas, message counts, sequence numbers, log times against
// host_timestamps.csv and image timestamps against frames.csv, and every pixel of the
// first depth, colour and mask image against the PNGs.
import assert from "node:assert/strict";
import { execFileSync, spawnSync } from "node:child_process";
import fs from "node:fs";
import os from "node:os";
import path from "node:path";
import { test } from "node:test";

import { McapStreamReader } from "@mcap/core";

import {
  decoderFor, decompressHandlers, messagesOn, openMcap, pngAsRawImageBytes, readPng, stampNs,
} from "./readers.mjs";
import { paperRigPath } from "../../support/rigs.mjs";

const TILTH = process.env.TILTH_BIN;
const RECORDING_TOOL = process.env.TILTH_RECORDING_BIN;
const CALIBRATION = paperRigPath();
const FRAMES = 3;

// Runs synthetic.scene -> mcap.writer and recording.image_folder_writer once.
function record() {
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), "tilth-mcap-js-"));
  const graph = {
    nodes: {
      scene: { type: "synthetic.scene",
               params: { calibration: CALIBRATION, preset: "flat", frames: FRAMES } },
      // Offline: every chunk compressed (a live recording stores those it cannot).
      mcap: { type: "mcap.writer",
              params: { path: path.join(dir, "scene.mcap"), calibration: CALIBRATION,
                        when_behind: "wait" } },
      folder: { type: "recording.image_folder_writer",
                params: { path: path.join(dir, "folder"), calibration: CALIBRATION } },
    },
    edges: [
      ["scene.raw", "mcap.raw"], ["scene.color", "mcap.color"], ["scene.truth", "mcap.truth"],
      ["scene.raw", "folder.raw"], ["scene.color", "folder.color"],
      ["scene.truth", "folder.truth"],
    ],
    runtime: { on_error: "stop" },
  };
  fs.writeFileSync(path.join(dir, "graph.json"), JSON.stringify(graph));
  execFileSync(TILTH, ["run", path.join(dir, "graph.json")], { stdio: "inherit" });
  return dir;
}

const dir = record();
const file = path.join(dir, "scene.mcap");
const folder = path.join(dir, "folder");
const readCsv = (name) => fs.readFileSync(path.join(folder, name), "utf8").trim().split("\n")
  .slice(1).map((line) => line.split(","));
const rows = readCsv("frames.csv");
const hostRows = readCsv("host_timestamps.csv");

const openReader = () => openMcap(file);

test("channels, schemas and message counts", async () => {
  const reader = await openReader();
  const topics = [...reader.channelsById.values()].map((channel) => channel.topic).sort();
  assert.deepEqual(topics, ["/color/calibration", "/color/image", "/tf", "/tof/calibration",
                            "/tof/raw", "/truth", "/truth/mask"]);
  // JSON messages; the images are RawImages. The rig (calibrations, pose) comes once.
  const json = { "/truth": "tilth.GroundTruth", "/tof/calibration": "foxglove.CameraCalibration",
                 "/color/calibration": "foxglove.CameraCalibration",
                 "/tf": "foxglove.FrameTransform" };
  for (const channel of reader.channelsById.values()) {
    const schema = reader.schemasById.get(channel.schemaId);
    const name = json[channel.topic];
    assert.equal(channel.messageEncoding, name ? "json" : "cdr");
    assert.equal(schema.encoding, name ? "jsonschema" : "ros2msg");
    assert.equal(schema.name, name ?? "foxglove_msgs/msg/RawImage");
    decoderFor(reader, channel.id);  // the schema parses
    const count = reader.statistics.channelMessageCounts.get(channel.id);
    const rig = ["/tof/calibration", "/color/calibration", "/tf"].includes(channel.topic);
    assert.equal(count, BigInt(rig ? 1 : FRAMES), channel.topic);
  }
  assert.equal(reader.statistics.messageCount, BigInt(4 * FRAMES + 3));
  assert.ok(reader.chunkIndexes.length >= 1);
  assert.ok(reader.chunkIndexes.every((chunk) => chunk.compression === "zstd"));
});

test("sequence numbers are the frames' ids, log times their host capture times", async () => {
  const reader = await openReader();
  const raw = await messagesOn(reader, "/tof/raw");
  const color = await messagesOn(reader, "/color/image");
  const truth = await messagesOn(reader, "/truth");
  const mask = await messagesOn(reader, "/truth/mask");
  const decodeTruth = decoderFor(reader, truth[0].channelId);
  const decodeImage = decoderFor(reader, raw[0].channelId);
  assert.equal(rows.length, FRAMES);
  assert.equal(hostRows.length, FRAMES);
  rows.forEach(([index, depthNs, colorNs], i) => {
    const [hostIndex, hostNs] = hostRows[i];
    assert.equal(hostIndex, index);
    for (const message of [raw[i], color[i], truth[i], mask[i]]) {
      assert.equal(message.sequence, Number(index));
      assert.equal(message.logTime, BigInt(hostNs));
      assert.equal(message.publishTime, BigInt(hostNs));
    }
    assert.equal(stampNs(decodeImage(raw[i]).timestamp), BigInt(depthNs));
    assert.equal(stampNs(decodeImage(color[i]).timestamp), BigInt(colorNs));
    assert.equal(decodeTruth(truth[i]).distance_mm, Number(rows[i][6]));
  });
});

test("images decode as Foxglove decodes them, to the image-folder PNGs' pixels", async () => {
  const reader = await openReader();
  const index = rows[0][0].padStart(6, "0");
  const expected = {
    "/tof/raw": { folder: "depth", encoding: "mono16", frameId: "tof", size: [640, 480, 1280] },
    "/color/image": { folder: "color", encoding: "bgr8", frameId: "color", size: [1280, 1024, 3840] },
    "/truth/mask": { folder: "mask", encoding: "mono8", frameId: "tof", size: [640, 480, 640] },
  };
  for (const [topic, want] of Object.entries(expected)) {
    const [message] = await messagesOn(reader, topic);
    const image = decoderFor(reader, message.channelId)(message);
    assert.equal(image.encoding, want.encoding, topic);
    assert.equal(image.frame_id, want.frameId, topic);
    assert.deepEqual([image.width, image.height, image.step], want.size, topic);
    assert.equal(stampNs(image.timestamp), BigInt(rows[0][topic === "/color/image" ? 2 : 1]),
                 topic);
    const png = pngAsRawImageBytes(readPng(path.join(folder, want.folder, `${index}.png`)));
    assert.ok(Buffer.from(image.data).equals(png), `${topic}: pixels differ from the PNG`);
  }
});

test("the calibration is attached and in the metadata", async () => {
  const reader = await openReader();
  const calibration = fs.readFileSync(CALIBRATION, "utf8");
  const attachments = [];
  for await (const attachment of reader.readAttachments({ validateCrcs: true })) {
    attachments.push(attachment);
  }
  const rig = attachments.find((attachment) => attachment.name === "rig.calib.json");
  assert.equal(rig.mediaType, "application/json");
  assert.equal(new TextDecoder().decode(rig.data), calibration);
  const metadata = [];
  for await (const record of reader.readMetadata({ name: "tilth.calibration" })) metadata.push(record);
  assert.equal(metadata.length, 1);
  assert.equal(metadata[0].metadata.get("json"), calibration);
  const release = fs
    .readFileSync(path.join(process.env.TILTH_SOURCE_DIR, "CMakeLists.txt"), "utf8")
    .match(/project\(Tilth VERSION ([0-9.]+)/)[1];
  const recording = [];
  for await (const record of reader.readMetadata({ name: "tilth.recording" })) recording.push(record);
  assert.equal(recording.length, 1);
  assert.equal(recording[0].metadata.get("tilth_version"), release);
});

test("the stream reader reads every record with valid CRCs", () => {
  const stream = new McapStreamReader({ validateCrcs: true, decompressHandlers });
  stream.append(fs.readFileSync(file));
  const counts = {};
  let record;
  while ((record = stream.nextRecord())) counts[record.type] = (counts[record.type] ?? 0) + 1;
  assert.ok(stream.done());
  assert.equal(counts.Message, 4 * FRAMES + 3);
  assert.equal(counts.Footer, 1);
  assert.equal(counts.DataEnd, 1);
});

// Runs `tilth-recording ARGS`: its exit code and output.
function recordingTool(...args) {
  const result = spawnSync(RECORDING_TOOL, args, { encoding: "utf8", timeout: 120_000 });
  return { code: result.status, stdout: result.stdout, stderr: result.stderr };
}

test("tilth recording info and repair", () => {
  const info = execFileSync(TILTH, ["recording", "info", file], { encoding: "utf8" });
  assert.match(info, /summary: {5}yes/);
  assert.match(info, /integrity: {3}every CRC matches/);
  assert.match(info, new RegExp(`/tof/raw  ${FRAMES} messages  foxglove_msgs/msg/RawImage \\(cdr\\)`));
  const cut = path.join(dir, "cut.mcap");
  const bytes = fs.readFileSync(file);
  fs.writeFileSync(cut, bytes.subarray(0, bytes.length - 100));
  const cutInfo = recordingTool("info", cut);
  assert.equal(cutInfo.code, 3);
  assert.match(cutInfo.stdout, /summary: {5}MISSING/);
  const repaired = path.join(dir, "repaired.mcap");
  assert.equal(recordingTool("repair", cut, repaired).code, 0);  // only the summary was cut
  assert.match(execFileSync(RECORDING_TOOL, ["info", repaired], { encoding: "utf8" }),
               /summary: {5}yes/);
});

// One chunk of three fails its CRC: info names it, and repair writes the other two into
// a new file that Foxglove's reader reads with every CRC checked, leaving the input as
// it was.
test("repair salvages the intact chunks, as @mcap/core reads them", async () => {
  const reader = await openReader();
  const chunks = [...reader.chunkIndexes].sort((a, b) => Number(a.chunkStartOffset - b.chunkStartOffset));
  assert.equal(chunks.length, FRAMES);
  const damaged = path.join(dir, "damaged.mcap");
  const bytes = Buffer.from(fs.readFileSync(file));
  const bad = chunks[1];
  bytes[Number(bad.chunkStartOffset + bad.chunkLength) - 40] ^= 0x01;
  fs.writeFileSync(damaged, bytes);

  const info = recordingTool("info", damaged);
  assert.equal(info.code, 3);
  assert.match(info.stdout, new RegExp(`Chunk at offset ${bad.chunkStartOffset}: `));
  const salvaged = path.join(dir, "salvaged.mcap");
  const repair = recordingTool("repair", damaged, salvaged);
  assert.equal(repair.code, 3, repair.stderr);
  assert.match(repair.stderr, new RegExp(`dropped ${bad.chunkLength} bytes at offset ${bad.chunkStartOffset}`));
  assert.ok(fs.readFileSync(damaged).equals(bytes));
  assert.equal(recordingTool("repair", damaged, damaged).code, 1);
  assert.ok(fs.readFileSync(damaged).equals(bytes));

  const repaired = await openMcap(salvaged);
  assert.equal(repaired.chunkIndexes.length, FRAMES - 1);
  const raw = await messagesOn(repaired, "/tof/raw");
  const original = await messagesOn(reader, "/tof/raw");
  assert.deepEqual(raw.map((message) => message.sequence),
                   [original[0].sequence, original[2].sequence]);
  assert.ok(Buffer.from(raw[1].data).equals(Buffer.from(original[2].data)));
});

test.after(() => fs.rmSync(dir, { recursive: true, force: true }));

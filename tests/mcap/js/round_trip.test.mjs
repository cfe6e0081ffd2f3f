// The round trip simulate -> MCAP -> image folder -> MCAP, with the `tilth` commands a
// user runs, checked by readers that share no code with Tilth (readers.mjs): both MCAP
// files hold the same messages (sequence numbers = frame ids, log and publish times =
// the host capture times, when the simulator rendered each frame, and the very bytes:
// every pixel, image timestamp = device time, frame_id and encoding), the folder holds
// the same pixels, device times (frames.csv), host times (host_timestamps.csv), ground
// truth (distance and mask) and frame ids, and the calibration is the same file all the
// way. Exporting the second MCAP file gives the folder again, file for file.
//
// A quarter-size rig keeps the simulator fast; case_c has straw, so the truth mask has
// soil, residue and mixed pixels. Once with bgr8 colour, once with a Bayer mosaic.
import assert from "node:assert/strict";
import { execFileSync } from "node:child_process";
import fs from "node:fs";
import os from "node:os";
import path from "node:path";
import { test } from "node:test";

import {
  attachmentsOf, decoderFor, messagesOn, openMcap, pngAsRawImageBytes, readPng, stampNs,
} from "./readers.mjs";
import { quarterRig } from "../../support/rigs.mjs";

const TILTH = process.env.TILTH_BIN;
const FRAMES = 4;
const TOPICS = ["/tof/raw", "/color/image", "/truth", "/truth/mask"];

const dir = fs.mkdtempSync(path.join(os.tmpdir(), "tilth-round-trip-"));
test.after(() => fs.rmSync(dir, { recursive: true, force: true }));

function tilth(...args) {
  return execFileSync(TILTH, args, { encoding: "utf8", stdio: ["ignore", "pipe", "inherit"] });
}

function readCsv(folder, name) {
  const [header, ...lines] = fs.readFileSync(path.join(folder, name), "utf8").trim().split("\n");
  const names = header.split(",");
  return lines.map((line) => Object.fromEntries(line.split(",").map((v, i) => [names[i], v])));
}

const nowNs = () => BigInt(Date.now()) * 1000000n;

function listFiles(folder) {
  return fs.readdirSync(folder, { recursive: true }).filter((name) =>
    fs.statSync(path.join(folder, name)).isFile()).sort();
}

async function roundTrip(colorFormat) {
  const calibration = quarterRig(dir);
  const work = path.join(dir, colorFormat);
  fs.mkdirSync(work);
  const first = path.join(work, "simulated.mcap");
  const folder = path.join(work, "folder");
  const second = path.join(work, "imported.mcap");
  const again = path.join(work, "folder-again");

  const simulationStart = nowNs();
  assert.match(tilth("simulate", first, "--preset", "case_c", "--frames", String(FRAMES),
                     "--seed", "11", "--calibration", calibration, "--color-format", colorFormat),
               new RegExp(`${FRAMES} frames \\(mcap\\)`));
  const simulationEnd = nowNs();
  assert.match(tilth("recording", "export", first, folder), new RegExp(`${FRAMES} frames from`));
  assert.match(tilth("recording", "import", folder, second), new RegExp(`${FRAMES} frames from`));
  tilth("recording", "export", second, again);

  const a = await openMcap(first);
  const b = await openMcap(second);
  const rows = readCsv(folder, "frames.csv");
  assert.equal(rows.length, FRAMES);
  const hostRows = readCsv(folder, "host_timestamps.csv");
  assert.deepEqual(hostRows.map((row) => row.index), rows.map((row) => row.index));
  const recording = JSON.parse(fs.readFileSync(path.join(folder, "recording.json")));
  assert.equal(recording.color_format, colorFormat);

  // The MCAP files: the same messages, byte for byte, in the same order.
  const messages = {};
  for (const topic of TOPICS) {
    const fromA = await messagesOn(a, topic);
    const fromB = await messagesOn(b, topic);
    assert.equal(fromA.length, FRAMES, topic);
    assert.equal(fromB.length, FRAMES, topic);
    fromA.forEach((message, i) => {
      const other = fromB[i];
      assert.equal(other.sequence, message.sequence, `${topic} ${i}: sequence`);
      assert.equal(other.logTime, message.logTime, `${topic} ${i}: log time`);
      assert.equal(other.publishTime, message.publishTime, `${topic} ${i}: publish time`);
      assert.ok(Buffer.from(other.data).equals(Buffer.from(message.data)), `${topic} ${i}: data`);
    });
    const decode = decoderFor(a, fromA[0].channelId);
    messages[topic] = fromA.map((message) => ({ message, decoded: decode(message) }));
  }

  // The folder against the first MCAP file, frame by frame.
  const maskValues = new Set();
  rows.forEach((row, i) => {
    const raw = messages["/tof/raw"][i];
    const color = messages["/color/image"][i];
    const truth = messages["/truth"][i];
    const mask = messages["/truth/mask"][i];
    assert.equal(BigInt(row.index), BigInt(raw.message.sequence), `frame ${i}: id`);
    // Log and publish times: the host capture time, the same for every message of the
    // frame, on the wall clock while the simulator ran; images keep their device times.
    const host = BigInt(hostRows[i].host_timestamp_ns);
    assert.ok(host >= simulationStart && host <= simulationEnd, `frame ${i}: host time ${host}`);
    if (i > 0) assert.ok(host > BigInt(hostRows[i - 1].host_timestamp_ns), `frame ${i}: host time`);
    for (const { message } of [raw, color, truth, mask]) {
      assert.equal(message.logTime, host, `frame ${i}: log time`);
      assert.equal(message.publishTime, host, `frame ${i}: publish time`);
    }
    assert.equal(stampNs(raw.decoded.timestamp), BigInt(row.depth_timestamp_ns), `frame ${i}: depth time`);
    assert.equal(stampNs(color.decoded.timestamp), BigInt(row.color_timestamp_ns),
                 `frame ${i}: colour time`);
    assert.notEqual(host, BigInt(row.depth_timestamp_ns));
    assert.equal(color.decoded.encoding, colorFormat);
    assert.equal(Number(row.ground_truth_mm), truth.decoded.distance_mm, `frame ${i}: truth`);
    assert.equal(truth.decoded.distance_mm, 518);
    assert.equal(truth.decoded.has_mask, true);
    for (const [column, image] of [["depth", raw], ["color", color], ["mask", mask]]) {
      const png = pngAsRawImageBytes(readPng(path.join(folder, row[column])));
      assert.ok(Buffer.from(image.decoded.data).equals(png), `frame ${i}: ${column} pixels`);
    }
    for (const value of mask.decoded.data) maskValues.add(value);
  });
  assert.deepEqual([...maskValues].sort((x, y) => x - y), [0, 128, 255]);

  // The calibration: the file given to the simulator, all the way through.
  const rig = fs.readFileSync(calibration);
  assert.ok(fs.readFileSync(path.join(folder, recording.calibration)).equals(rig));
  for (const reader of [a, b]) {
    const attachment = (await attachmentsOf(reader)).get("rig.calib.json");
    assert.ok(Buffer.from(attachment.data).equals(rig));
    const metadata = [];
    for await (const record of reader.readMetadata({ name: "tilth.calibration" })) {
      metadata.push(record);
    }
    assert.equal(metadata[0].metadata.get("json"), rig.toString("utf8"));
  }

  // The second file exports to the same folder, file for file.
  assert.deepEqual(listFiles(again), listFiles(folder));
  for (const name of listFiles(folder)) {
    if (name === "recording.json") continue;  // its description names the MCAP file
    assert.ok(fs.readFileSync(path.join(again, name)).equals(fs.readFileSync(path.join(folder, name))),
              name);
  }
}

test("simulate -> MCAP -> image folder -> MCAP keeps everything (bgr8)", () => roundTrip("bgr8"));
test("simulate -> MCAP -> image folder -> MCAP keeps everything (Bayer)", () =>
  roundTrip("bayer_grbg8"));

// An independent reader of an MCAP file written by `tilth run`: Foxglove's @mcap/core
// (with @foxglove/wasm-zstd for the chunks) reads a recording of synthetic.scene made by
// mcap.writer, and checks it against the image-folder recording that
// recording.image_folder_writer made of the same frames in the same graph: channel
// names and schemas, message counts, sequence numbers and log times against frames.csv,
// and every pixel of the first depth and colour image against the PNGs, decoded by the
// small PNG reader below (zlib from Node, no image library).
import assert from "node:assert/strict";
import { execFileSync } from "node:child_process";
import fs from "node:fs";
import os from "node:os";
import path from "node:path";
import { test } from "node:test";
import zlib from "node:zlib";

import { McapIndexedReader, McapStreamReader } from "@mcap/core";
import zstd from "@foxglove/wasm-zstd";

const TILTH = process.env.TILTH_BIN;
const TOOL = process.env.TILTH_MCAP_TOOL;
const SOURCE = process.env.TILTH_SOURCE_DIR;
const CALIBRATION = path.join(SOURCE, "calib", "paper_rig.calib.json");
const FRAMES = 3;

// {width, height, bitDepth, channels, data}: a non-interlaced gray or RGB PNG, samples as
// stored (16-bit big-endian, RGB order).
function readPng(file) {
  const bytes = fs.readFileSync(file);
  assert.deepEqual([...bytes.subarray(0, 8)], [0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a]);
  let position = 8;
  let header;
  const idat = [];
  while (position < bytes.length) {
    const length = bytes.readUInt32BE(position);
    const kind = bytes.toString("latin1", position + 4, position + 8);
    const body = bytes.subarray(position + 8, position + 8 + length);
    if (kind === "IHDR") {
      header = {
        width: body.readUInt32BE(0), height: body.readUInt32BE(4), bitDepth: body[8],
        colorType: body[9], interlace: body[12],
      };
    } else if (kind === "IDAT") {
      idat.push(body);
    }
    position += 12 + length;
  }
  assert.equal(header.interlace, 0);
  const channels = { 0: 1, 2: 3 }[header.colorType];
  const pixelBytes = (channels * header.bitDepth) / 8;
  const stride = header.width * pixelBytes;
  const raw = zlib.inflateSync(Buffer.concat(idat));
  const data = Buffer.alloc(stride * header.height);
  for (let y = 0; y < header.height; ++y) {
    const filter = raw[y * (stride + 1)];
    const line = raw.subarray(y * (stride + 1) + 1, (y + 1) * (stride + 1));
    for (let x = 0; x < stride; ++x) {
      const left = x >= pixelBytes ? data[y * stride + x - pixelBytes] : 0;
      const up = y > 0 ? data[(y - 1) * stride + x] : 0;
      const upLeft = x >= pixelBytes && y > 0 ? data[(y - 1) * stride + x - pixelBytes] : 0;
      let predictor = 0;
      if (filter === 1) predictor = left;
      else if (filter === 2) predictor = up;
      else if (filter === 3) predictor = (left + up) >> 1;
      else if (filter === 4) {
        const p = left + up - upLeft;
        const pa = Math.abs(p - left);
        const pb = Math.abs(p - up);
        const pc = Math.abs(p - upLeft);
        predictor = pa <= pb && pa <= pc ? left : pb <= pc ? up : upLeft;
      }
      data[y * stride + x] = (line[x] + predictor) & 0xff;
    }
  }
  return { width: header.width, height: header.height, bitDepth: header.bitDepth, channels, data };
}

function fileReadable(file) {
  const handle = fs.openSync(file, "r");
  return {
    size: async () => BigInt(fs.fstatSync(handle).size),
    read: async (offset, size) => {
      const buffer = Buffer.alloc(Number(size));
      fs.readSync(handle, buffer, 0, Number(size), Number(offset));
      return buffer;
    },
  };
}

// Runs synthetic.scene -> mcap.writer and recording.image_folder_writer once.
function record() {
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), "tilth-mcap-js-"));
  const graph = {
    nodes: {
      scene: { type: "synthetic.scene",
               params: { calibration: CALIBRATION, preset: "flat", frames: FRAMES } },
      mcap: { type: "mcap.writer",
               params: { path: path.join(dir, "scene.mcap"), calibration: CALIBRATION } },
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
const rows = fs.readFileSync(path.join(folder, "frames.csv"), "utf8").trim().split("\n").slice(1)
  .map((line) => line.split(","));

async function openReader() {
  await zstd.isLoaded;
  return McapIndexedReader.Initialize({
    readable: fileReadable(file),
    decompressHandlers: { zstd: (data, size) => zstd.decompress(data, Number(size)) },
  });
}

async function messagesOn(reader, topic) {
  const messages = [];
  for await (const message of reader.readMessages({ topics: [topic], validateCrcs: true })) {
    messages.push(message);
  }
  return messages;
}

test("channels, schemas and message counts", async () => {
  const reader = await openReader();
  const topics = [...reader.channelsById.values()].map((channel) => channel.topic).sort();
  assert.deepEqual(topics, ["/color/image", "/tof/raw", "/truth", "/truth/mask"]);
  for (const channel of reader.channelsById.values()) {
    const schema = reader.schemasById.get(channel.schemaId);
    assert.equal(channel.messageEncoding, "json");
    assert.equal(schema.encoding, "jsonschema");
    assert.equal(schema.name, channel.topic === "/truth" ? "tilth.GroundTruth" : "foxglove.RawImage");
    JSON.parse(new TextDecoder().decode(schema.data));
    const count = reader.statistics.channelMessageCounts.get(channel.id);
    assert.equal(count, BigInt(FRAMES), channel.topic);
  }
  assert.equal(reader.statistics.messageCount, BigInt(4 * FRAMES));
  assert.ok(reader.chunkIndexes.length >= 1);
  assert.ok(reader.chunkIndexes.every((chunk) => chunk.compression === "zstd"));
});

test("sequence numbers and log times are the frames' ids and device times", async () => {
  const reader = await openReader();
  const raw = await messagesOn(reader, "/tof/raw");
  const color = await messagesOn(reader, "/color/image");
  const truth = await messagesOn(reader, "/truth");
  assert.equal(rows.length, FRAMES);
  rows.forEach(([index, depthNs, colorNs], i) => {
    assert.equal(raw[i].sequence, Number(index));
    assert.equal(raw[i].logTime, BigInt(depthNs));
    assert.equal(raw[i].publishTime, BigInt(depthNs));
    assert.equal(color[i].sequence, Number(index));
    assert.equal(color[i].logTime, BigInt(colorNs));
    assert.equal(truth[i].logTime, BigInt(depthNs));
    const distance = JSON.parse(new TextDecoder().decode(truth[i].data)).distance_mm;
    assert.ok(Math.abs(distance - Number(rows[i][6])) < 0.01, `${distance} vs ${rows[i][6]}`);
  });
});

test("image bytes are the image-folder PNGs' pixels", async () => {
  const reader = await openReader();
  const [raw] = await messagesOn(reader, "/tof/raw");
  const [color] = await messagesOn(reader, "/color/image");
  const [mask] = await messagesOn(reader, "/truth/mask");
  const index = rows[0][0].padStart(6, "0");

  const depth = JSON.parse(new TextDecoder().decode(raw.data));
  const depthPng = readPng(path.join(folder, "depth", `${index}.png`));
  assert.equal(depth.encoding, "mono16");
  assert.equal(depth.frame_id, "tof");
  assert.deepEqual([depth.width, depth.height, depth.step], [640, 480, 1280]);
  assert.deepEqual([depthPng.width, depthPng.height, depthPng.bitDepth], [640, 480, 16]);
  const depthBytes = Buffer.from(depth.data, "base64");
  assert.equal(depthBytes.length, 640 * 480 * 2);
  const depthStamp = BigInt(depth.timestamp.sec) * 1000000000n + BigInt(depth.timestamp.nsec);
  assert.equal(depthStamp, raw.logTime);
  for (let i = 0; i < 640 * 480; ++i) {
    // mono16 little-endian; PNG big-endian.
    if (depthBytes.readUInt16LE(2 * i) !== depthPng.data.readUInt16BE(2 * i)) {
      assert.fail(`depth pixel ${i}: ${depthBytes.readUInt16LE(2 * i)} vs PNG ${depthPng.data.readUInt16BE(2 * i)}`);
    }
  }

  const image = JSON.parse(new TextDecoder().decode(color.data));
  const colorPng = readPng(path.join(folder, "color", `${index}.png`));
  assert.equal(image.encoding, "bgr8");
  assert.deepEqual([image.width, image.height, image.step], [1280, 1024, 3840]);
  assert.equal(colorPng.channels, 3);
  const colorBytes = Buffer.from(image.data, "base64");
  for (let i = 0; i < 1280 * 1024; ++i) {
    // bgr8 against the PNG's RGB.
    for (let c = 0; c < 3; ++c) {
      if (colorBytes[3 * i + c] !== colorPng.data[3 * i + 2 - c]) {
        assert.fail(`colour pixel ${i} channel ${c} differs from the PNG`);
      }
    }
  }

  const maskImage = JSON.parse(new TextDecoder().decode(mask.data));
  const maskPng = readPng(path.join(folder, "mask", `${index}.png`));
  assert.equal(maskImage.encoding, "mono8");
  assert.ok(Buffer.from(maskImage.data, "base64").equals(maskPng.data));
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
});

test("the stream reader reads every record with valid CRCs", () => {
  const stream = new McapStreamReader({
    validateCrcs: true,
    decompressHandlers: { zstd: (data, size) => zstd.decompress(data, Number(size)) },
  });
  stream.append(fs.readFileSync(file));
  const counts = {};
  let record;
  while ((record = stream.nextRecord())) counts[record.type] = (counts[record.type] ?? 0) + 1;
  assert.ok(stream.done());
  assert.equal(counts.Message, 4 * FRAMES);
  assert.equal(counts.Footer, 1);
  assert.equal(counts.DataEnd, 1);
});

test("tilth-mcap info and repair", () => {
  const info = execFileSync(TOOL, ["info", file], { encoding: "utf8" });
  assert.match(info, /summary: {5}yes/);
  assert.match(info, new RegExp(`/tof/raw  ${FRAMES} messages  foxglove.RawImage \\(json\\)`));
  const cut = path.join(dir, "cut.mcap");
  const bytes = fs.readFileSync(file);
  fs.writeFileSync(cut, bytes.subarray(0, bytes.length - 100));
  assert.match(execFileSync(TOOL, ["info", cut], { encoding: "utf8" }), /summary: {5}MISSING/);
  execFileSync(TOOL, ["repair", cut], { encoding: "utf8" });
  assert.match(execFileSync(TOOL, ["info", cut], { encoding: "utf8" }), /summary: {5}yes/);
});

test.after(() => fs.rmSync(dir, { recursive: true, force: true }));

// Readers that share no code with Tilth, for the tests of this folder: Foxglove's
// @mcap/core for MCAP files (@foxglove/wasm-zstd for zstd chunks), Foxglove's ROS 2
// message parser and CDR deserializer for the images (what Foxglove itself decodes them
// with, driven by the schema text in the file), and a small PNG decoder (zlib from Node,
// no image library) for image-folder recordings.
import assert from "node:assert/strict";
import fs from "node:fs";
import zlib from "node:zlib";

import { McapIndexedReader } from "@mcap/core";
import { parse as parseMessageDefinition } from "@foxglove/rosmsg";
import { MessageReader } from "@foxglove/rosmsg2-serialization";
import zstd from "@foxglove/wasm-zstd";

// {width, height, bitDepth, channels, data}: a non-interlaced gray or RGB PNG, samples as
// stored (16-bit big-endian, RGB order).
export function readPng(file) {
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

// The PNG's samples in the byte order of a RawImage: 16-bit little-endian, colour BGR.
export function pngAsRawImageBytes(png) {
  const out = Buffer.alloc(png.data.length);
  if (png.bitDepth === 16) {
    for (let i = 0; i < out.length; i += 2) out.writeUInt16LE(png.data.readUInt16BE(i), i);
  } else if (png.channels === 3) {
    for (let i = 0; i < out.length; i += 3) {
      out[i] = png.data[i + 2];
      out[i + 1] = png.data[i + 1];
      out[i + 2] = png.data[i];
    }
  } else {
    png.data.copy(out);
  }
  return out;
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

export const decompressHandlers = { zstd: (data, size) => zstd.decompress(data, Number(size)) };

export async function openMcap(file) {
  await zstd.isLoaded;
  return McapIndexedReader.Initialize({ readable: fileReadable(file), decompressHandlers });
}

// Every message of `topic`, in log-time order, CRCs checked.
export async function messagesOn(reader, topic) {
  const messages = [];
  for await (const message of reader.readMessages({ topics: [topic], validateCrcs: true })) {
    messages.push(message);
  }
  return messages;
}

// Decodes a message of its channel as Foxglove does: ROS 2 CDR with the schema's
// ros2msg definition, or JSON.
export function decoderFor(reader, channelId) {
  const channel = reader.channelsById.get(channelId);
  const schema = reader.schemasById.get(channel.schemaId);
  const text = new TextDecoder().decode(schema.data);
  if (channel.messageEncoding === "cdr") {
    assert.equal(schema.encoding, "ros2msg");
    const cdr = new MessageReader(parseMessageDefinition(text, { ros2: true }));
    return (message) => cdr.readMessage(message.data);
  }
  assert.equal(channel.messageEncoding, "json");
  assert.equal(schema.encoding, "jsonschema");
  JSON.parse(text);
  return (message) => JSON.parse(new TextDecoder().decode(message.data));
}

export function stampNs(timestamp) {
  return BigInt(timestamp.sec) * 1000000000n + BigInt(timestamp.nanosec ?? timestamp.nsec);
}

export async function attachmentsOf(reader) {
  const attachments = new Map();
  for await (const attachment of reader.readAttachments({ validateCrcs: true })) {
    attachments.set(attachment.name, attachment);
  }
  return attachments;
}

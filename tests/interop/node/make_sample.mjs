#!/usr/bin/env node
// Writes a small MCAP with @mcap/core's writer, so that mcap_check.mjs can be shown to pass and to fail
// without fieldguard's own writer.
//
//   node make_sample.mjs OUT.mcap [--uncompressed] [--invalid]
//
// /points: foxglove.PointCloud (x, y, z float32, intensity uint8; 16 bytes a point); /decision: a
// fieldguard.Decision. --invalid leaves point_stride out of the last point cloud.
import fs from "node:fs";
import { McapWriter } from "@mcap/core";
import zstd from "@foxglove/wasm-zstd";

const [out, ...flags] = process.argv.slice(2);
if (!out || flags.some((f) => !["--uncompressed", "--invalid"].includes(f))) {
  process.stderr.write("usage: node make_sample.mjs OUT.mcap [--uncompressed] [--invalid]\n");
  process.exit(2);
}
await zstd.isLoaded;

const vec3 = { type: "object", required: ["x", "y", "z"], properties: { x: { type: "number" }, y: { type: "number" }, z: { type: "number" } } };
const time = { type: "object", required: ["sec", "nsec"], properties: { sec: { type: "integer", minimum: 0 }, nsec: { type: "integer", minimum: 0, maximum: 999999999 } } };
const pointCloudSchema = {
  $schema: "https://json-schema.org/draft/2020-12/schema",
  title: "foxglove.PointCloud",
  type: "object",
  required: ["timestamp", "frame_id", "pose", "point_stride", "fields", "data"],
  properties: {
    timestamp: time,
    frame_id: { type: "string" },
    pose: {
      type: "object",
      required: ["position", "orientation"],
      properties: { position: vec3, orientation: { ...vec3, required: ["x", "y", "z", "w"], properties: { ...vec3.properties, w: { type: "number" } } } },
    },
    point_stride: { type: "integer", minimum: 0 },
    fields: {
      type: "array",
      items: {
        type: "object",
        required: ["name", "offset", "type"],
        properties: { name: { type: "string" }, offset: { type: "integer", minimum: 0 }, type: { type: "integer", minimum: 0, maximum: 8 } },
      },
    },
    data: { type: "string", contentEncoding: "base64" },
  },
};
const decisionSchema = {
  $schema: "https://json-schema.org/draft/2020-12/schema",
  title: "fieldguard.Decision",
  type: "object",
  required: ["timestamp", "stop", "reason"],
  additionalProperties: false,
  properties: { timestamp: time, stop: { type: "boolean" }, reason: { type: "string" } },
};

const chunks = [];
let position = 0n;
const writer = new McapWriter({
  writable: { write: async (b) => { chunks.push(Buffer.from(b)); position += BigInt(b.length); }, position: () => position },
  chunkSize: 512, // several chunks from a few messages
  compressChunk: flags.includes("--uncompressed") ? undefined : (data) => ({ compression: "zstd", compressedData: zstd.compress(data, 1) }),
});
await writer.start({ profile: "", library: "fieldguard make_sample.mjs" });
const json = (o) => new TextEncoder().encode(JSON.stringify(o));
const channel = async (topic, name, schema) => writer.registerChannel({
  topic, messageEncoding: "json", metadata: new Map(),
  schemaId: await writer.registerSchema({ name, encoding: "jsonschema", data: json(schema) }),
});
const points = await channel("/points", "foxglove.PointCloud", pointCloudSchema);
const decision = await channel("/decision", "fieldguard.Decision", decisionSchema);

const FRAMES = 5;
for (let i = 0; i < FRAMES; i++) {
  const t = 1_700_000_000n * 1_000_000_000n + BigInt(i) * 100_000_000n;
  const timestamp = { sec: Number(t / 1_000_000_000n), nsec: Number(t % 1_000_000_000n) };
  const data = Buffer.alloc(3 * 16);
  for (let p = 0; p < 3; p++) {
    data.writeFloatLE(p + i, p * 16);
    data.writeFloatLE(-p, p * 16 + 4);
    data.writeFloatLE(0.5, p * 16 + 8);
    data.writeUInt8(100 + p, p * 16 + 12);
  }
  const cloud = {
    timestamp, frame_id: "lidar",
    pose: { position: { x: 0, y: 0, z: 0 }, orientation: { x: 0, y: 0, z: 0, w: 1 } },
    point_stride: 16,
    fields: [{ name: "x", offset: 0, type: 7 }, { name: "y", offset: 4, type: 7 }, { name: "z", offset: 8, type: 7 }, { name: "intensity", offset: 12, type: 1 }],
    data: data.toString("base64"),
  };
  if (flags.includes("--invalid") && i === FRAMES - 1) delete cloud.point_stride;
  const message = (channelId, sequence, obj) => writer.addMessage({ channelId, sequence, logTime: t, publishTime: t, data: json(obj) });
  await message(points, i, cloud);
  await message(decision, i, { timestamp, stop: i % 2 === 1, reason: i % 2 ? "obstacle in zone" : "clear" });
}
await writer.end();
fs.writeFileSync(out, Buffer.concat(chunks));

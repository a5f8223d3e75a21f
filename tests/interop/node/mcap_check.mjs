#!/usr/bin/env node
// Checks an MCAP file with readers that share no code with fieldguard's writer: @mcap/core reads it twice
// (record by record, then through the summary's indexes), the CRCs @mcap/core leaves unchecked are computed
// here, and every JSON message is validated against @foxglove/schemas' JSON schema for foxglove.* names and
// against the schema the file itself carries.
//
//   node mcap_check.mjs FILE.mcap [--expect-topic TOPIC]... [--min-messages N] [--dump TOPIC OUT.jsonl]...
//
// Prints one JSON line; exits 1 on any error, 2 on a usage error. --dump writes each message of TOPIC, as
// this reader decoded it, as one JSON line of OUT (in file order), for a test to compare with what it expects.
import fs from "node:fs";
import { McapIndexedReader, McapStreamReader } from "@mcap/core";
import zstd from "@foxglove/wasm-zstd";
import lz4 from "@foxglove/wasm-lz4";
import { makeChecker } from "./foxglove_validate.mjs";

function usage(message) {
  process.stderr.write(`mcap_check: ${message}\nusage: node mcap_check.mjs FILE.mcap [--expect-topic TOPIC]... [--min-messages N] [--dump TOPIC OUT.jsonl]...\n`);
  process.exit(2);
}

const args = { file: undefined, topics: [], minMessages: 0, dumps: new Map() };
for (let i = 2; i < process.argv.length; i++) {
  const a = process.argv[i];
  if (a === "--dump") {
    const topic = process.argv[++i];
    const out = process.argv[++i];
    if (out === undefined) usage("--dump needs a topic and a file");
    args.dumps.set(topic, { path: out, lines: [] });
  } else if (a === "--expect-topic" || a === "--min-messages") {
    const v = process.argv[++i];
    if (v === undefined) usage(`${a} needs a value`);
    if (a === "--expect-topic") args.topics.push(v);
    else if (!/^\d+$/.test(v)) usage(`--min-messages: not a count: ${v}`);
    else args.minMessages = Number(v);
  } else if (a.startsWith("-")) usage(`unknown option ${a}`);
  else if (args.file !== undefined) usage("one file only");
  else args.file = a;
}
if (args.file === undefined) usage("no file");

const errors = [];
let errorCount = 0;
const fail = (msg) => { if (errorCount++ < 20) errors.push(msg); };

// CRC-32 (IEEE 802.3, reflected, polynomial 0xEDB88320): the one the MCAP specification uses.
const CRC_TABLE = new Uint32Array(256).map((_, n) => {
  let c = n;
  for (let k = 0; k < 8; k++) c = c & 1 ? 0xedb88320 ^ (c >>> 1) : c >>> 1;
  return c;
});
function crc32(bytes) {
  let c = 0xffffffff;
  for (let i = 0; i < bytes.length; i++) c = CRC_TABLE[(c ^ bytes[i]) & 0xff] ^ (c >>> 8);
  return (c ^ 0xffffffff) >>> 0;
}

// @mcap/core does not compare the decompressed length with uncompressed_size; a short result would only
// surface later as a parse error.
const sized = (name, fn) => (data, size) => {
  let out;
  try {
    out = fn(data, Number(size));
  } catch (e) {
    throw new Error(`${name} chunk does not decompress: ${e.message}`);
  }
  if (out.length !== Number(size)) throw new Error(`${name} chunk decompressed to ${out.length} bytes, uncompressed_size ${size}`);
  return out;
};
await Promise.all([zstd.isLoaded, lz4.isLoaded]);
const decompressHandlers = { zstd: sized("zstd", zstd.decompress), lz4: sized("lz4", lz4) };

// --- JSON schema validators (foxglove_validate.mjs), checked once per channel ---------------------------
// A channel's setup error is reported once, not per message.
const checkers = new Map();
const utf8 = new TextDecoder("utf-8", { fatal: true });
function checkerFor(channel, schema) {
  if (checkers.has(channel.id)) return checkers.get(channel.id);
  let checker;
  try {
    if (channel.messageEncoding !== "json") throw new Error(`message encoding "${channel.messageEncoding}", expected "json"`);
    if (!schema) throw new Error(`schema id ${channel.schemaId} not found (schemaless channels are not expected)`);
    if (schema.encoding !== "jsonschema") throw new Error(`schema ${schema.name}: encoding "${schema.encoding}", expected "jsonschema"`);
    // The file's own schema is always checked too: an empty one is a setup error, not a skipped check.
    const text = utf8.decode(schema.data);
    if (text === "") throw new Error(`schema ${schema.name}: empty`);
    checker = makeChecker(schema.name, text);
  } catch (e) {
    checker = { setupError: `channel ${channel.id} (${channel.topic}): ${e.message}` };
    fail(checker.setupError);
  }
  checkers.set(channel.id, checker);
  return checker;
}

// --- the file --------------------------------------------------------------------------------------------
let buf;
try {
  buf = fs.readFileSync(args.file);
} catch (e) {
  fail(`cannot read: ${e.message}`);
  buf = Buffer.alloc(0);
}

const summary = { file: args.file, records: {}, messages: 0, topics: {}, schemas: [], chunks: 0, compression: [], errors };

// 1. Top-level framing walked here, for the offsets the two CRCs @mcap/core leaves unchecked need.
function checkSectionCrcs() {
  const MAGIC = Buffer.from([0x89, 0x4d, 0x43, 0x41, 0x50, 0x30, 0x0d, 0x0a]);
  if (buf.length < 16 || !buf.subarray(0, 8).equals(MAGIC) || !buf.subarray(-8).equals(MAGIC)) {
    fail("crc: file does not start and end with the MCAP magic");
    return;
  }
  let pos = 8, dataEnd, footer;
  while (pos + 9 <= buf.length - 8) {
    const opcode = buf[pos];
    const len = buf.readBigUInt64LE(pos + 1);
    if (BigInt(pos + 9) + len > BigInt(buf.length - 8)) break;
    if (opcode === 0x0f && dataEnd === undefined) dataEnd = pos;
    if (opcode === 0x02) { footer = pos; break; }
    pos += 9 + Number(len);
  }
  if (dataEnd === undefined || footer === undefined) {
    fail("crc: no Data End or no Footer record found walking the top-level records");
    return;
  }
  // From the leading magic up to Data End, as the specification counts the data section.
  const dataSectionCrc = buf.readUInt32LE(dataEnd + 9);
  const dataComputed = dataSectionCrc === 0 ? 0 : crc32(buf.subarray(0, dataEnd));
  if (dataSectionCrc === 0) fail("crc: data_section_crc is 0 (not computed)");
  else if (dataComputed !== dataSectionCrc) fail(`crc: data_section_crc mismatch: computed ${dataComputed}, recorded ${dataSectionCrc}`);
  if (footer + 9 + 20 + 8 !== buf.length) fail(`crc: Footer at ${footer} is not the last record before the magic`);
  const summaryStart = buf.readBigUInt64LE(footer + 9);
  const summaryCrc = buf.readUInt32LE(footer + 25);
  const dataEndEnd = dataEnd + 9 + Number(buf.readBigUInt64LE(dataEnd + 1));
  if (summaryStart === 0n) fail("crc: footer summary_start is 0 (no summary section)");
  else if (Number(summaryStart) !== dataEndEnd) fail(`crc: summary_start ${summaryStart} is not right after Data End (${dataEndEnd})`);
  else if (summaryCrc === 0) fail("crc: summary_crc is 0 (not computed)");
  else {
    const computed = crc32(buf.subarray(Number(summaryStart), buf.length - 8 - 4));
    if (computed !== summaryCrc) fail(`crc: summary_crc mismatch: computed ${computed}, recorded ${summaryCrc}`);
  }
}
if (buf.length > 0) checkSectionCrcs();

// 2. Record by record: counts, chunk CRCs (@mcap/core), every message decoded and validated.
const schemas = new Map(), channels = new Map();
const perChannel = new Map();
let statistics, logMin, logMax, chunk;
const compression = new Set();
const streamOk = (() => {
  if (buf.length === 0) return false;
  const reader = new McapStreamReader({ includeChunks: true, validateCrcs: true, decompressHandlers });
  try {
    // Fed in slices so records that straddle appends are exercised too.
    for (let off = 0; off < buf.length; off += 1 << 22) {
      reader.append(buf.subarray(off, off + (1 << 22)));
      for (let r; (r = reader.nextRecord()); ) onRecord(r);
    }
  } catch (e) {
    fail(`stream: ${e.message}`);
    return false;
  }
  if (!reader.done()) fail("stream: ended before the Footer and closing magic (truncated?)");
  return reader.done();
})();

function onRecord(r) {
  const name = r.type === "Unknown" ? `Unknown(0x${r.opcode.toString(16)})` : r.type;
  summary.records[name] = (summary.records[name] ?? 0) + 1;
  switch (r.type) {
    case "Schema": {
      const prev = schemas.get(r.id);
      if (prev && (prev.name !== r.name || prev.encoding !== r.encoding || !Buffer.from(prev.data).equals(Buffer.from(r.data))))
        fail(`stream: Schema id ${r.id} recorded twice with different content`);
      schemas.set(r.id, r);
      break;
    }
    case "Channel":
      channels.set(r.id, r); // @mcap/core already throws when a repeat differs
      break;
    case "Chunk":
      chunk = r;
      summary.chunks++;
      compression.add(r.compression === "" ? "none" : r.compression);
      if (r.uncompressedCrc === 0) fail(`stream: chunk ${summary.chunks}: uncompressed_crc is 0 (not computed)`);
      break;
    case "Statistics":
      statistics = r;
      break;
    case "Message":
      onMessage(r);
      break;
    default:
      // Only Schema, Channel and Message records sit in a chunk: anything else ends the current one.
      chunk = undefined;
  }
}

function onMessage(m) {
  summary.messages++;
  perChannel.set(m.channelId, (perChannel.get(m.channelId) ?? 0) + 1);
  const channel = channels.get(m.channelId);
  summary.topics[channel.topic] = (summary.topics[channel.topic] ?? 0) + 1;
  if (logMin === undefined || m.logTime < logMin) logMin = m.logTime;
  if (logMax === undefined || m.logTime > logMax) logMax = m.logTime;
  const where = `message ${channel.topic} log_time ${m.logTime}`;
  if (chunk && (m.logTime < chunk.messageStartTime || m.logTime > chunk.messageEndTime))
    fail(`${where}: outside its chunk's [${chunk.messageStartTime}, ${chunk.messageEndTime}]`);
  const checker = checkerFor(channel, schemas.get(channel.schemaId));
  if (checker.setupError) return;
  let obj;
  try {
    obj = JSON.parse(utf8.decode(m.data));
  } catch (e) {
    fail(`${where}: not UTF-8 JSON: ${e.message}`);
    return;
  }
  for (const p of checker(obj)) fail(`${where}: ${p}`);
  args.dumps.get(channel.topic)?.lines.push(JSON.stringify(obj));
}

summary.schemas = [...new Set([...schemas.values()].sort((a, b) => a.id - b.id).map((s) => s.name))];
summary.compression = [...compression].sort();

function compareCounts(label, counts, stats) {
  const ids = new Set([...counts.keys(), ...stats.channelMessageCounts.keys()]);
  for (const id of ids) {
    const want = Number(stats.channelMessageCounts.get(id) ?? 0n);
    if ((counts.get(id) ?? 0) !== want) fail(`${label}: channel ${id}: ${counts.get(id) ?? 0} messages, Statistics says ${want}`);
  }
}
if (streamOk) {
  if (!statistics) fail("stream: no Statistics record");
  else {
    const s = statistics;
    const expect = [
      ["message_count", Number(s.messageCount), summary.messages],
      ["chunk_count", s.chunkCount, summary.chunks],
      ["schema_count", s.schemaCount, schemas.size],
      ["channel_count", s.channelCount, channels.size],
    ];
    if (summary.messages > 0) expect.push(["message_start_time", s.messageStartTime, logMin], ["message_end_time", s.messageEndTime, logMax]);
    for (const [field, said, seen] of expect) if (said !== seen) fail(`stream: Statistics ${field} ${said}, read ${seen}`);
    compareCounts("stream", perChannel, s);
  }
}

// 3. Through the index: the summary CRC (@mcap/core checks it), chunk indexes, message indexes.
if (buf.length > 0) {
  try {
    const readable = {
      size: async () => BigInt(buf.length),
      read: async (offset, length) => {
        if (offset + length > BigInt(buf.length)) throw new Error(`read of ${length} at ${offset} is past the end`);
        return buf.subarray(Number(offset), Number(offset + length));
      },
    };
    const reader = await McapIndexedReader.Initialize({ readable, decompressHandlers });
    const counts = new Map();
    let n = 0;
    for await (const m of reader.readMessages()) {
      n++;
      counts.set(m.channelId, (counts.get(m.channelId) ?? 0) + 1);
    }
    if (streamOk && n !== summary.messages) fail(`index: ${n} messages through the index, ${summary.messages} read in sequence`);
    if (!reader.statistics) fail("index: no Statistics record in the summary");
    else compareCounts("index", counts, reader.statistics);
    for (const [id, c] of channels) {
      if (reader.channelsById.get(id)?.topic !== c.topic) fail(`index: channel ${id} (${c.topic}) missing from the summary`);
      if (c.schemaId !== 0 && !reader.schemasById.has(c.schemaId)) fail(`index: schema ${c.schemaId} missing from the summary`);
    }
  } catch (e) {
    fail(`index: ${e.message}`);
  }
}

for (const t of args.topics) if (!summary.topics[t]) fail(`expected topic ${t}: no messages`);
if (summary.messages < args.minMessages) fail(`${summary.messages} messages, fewer than --min-messages ${args.minMessages}`);
if (errorCount > 20) errors.push(`... and ${errorCount - 20} more`);

for (const { path, lines } of args.dumps.values()) fs.writeFileSync(path, lines.map((l) => l + "\n").join(""));
process.stdout.write(JSON.stringify(summary) + "\n");
process.exit(errorCount > 0 ? 1 : 0);

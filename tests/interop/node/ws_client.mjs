#!/usr/bin/env node
// A Foxglove WebSocket client built from Foxglove's own client library (@foxglove/ws-protocol over the `ws`
// package), as a viewer would connect to `fieldguard run`'s view server: it subscribes to every advertised
// channel and validates every message against @foxglove/schemas (foxglove.* names) and against the schema the
// advertise carries (foxglove_validate.mjs), sharing no code with fieldguard.
//
//   node ws_client.mjs ws://HOST:PORT [--seconds S] [--until-topic TOPIC:N]... [--dump TOPIC FILE]...
//
// Runs S seconds (default 10), or less when every --until-topic has N messages. Prints one JSON line:
// {"url","serverInfo","channels","messages":{topic:count},"bytes":{topic:bytes},"statuses","errors"}.
// Exit 1 on a validation error, a level-2 status, the server closing first, or an --until-topic not reached;
// 2 on a usage error. --dump writes each decoded message of TOPIC as one JSON line of FILE, in arrival order.
import fs from "node:fs";
import WebSocket from "ws";
import wsProtocol from "@foxglove/ws-protocol"; // CommonJS whose named exports Node cannot see from ESM
import { makeChecker } from "./foxglove_validate.mjs";

const USAGE = "usage: node ws_client.mjs ws://HOST:PORT [--seconds S] [--until-topic TOPIC:N]... [--dump TOPIC FILE]...";
function usage(message) {
  process.stderr.write(`ws_client: ${message}\n${USAGE}\n`);
  process.exit(2);
}

const args = { url: undefined, seconds: 10, until: new Map(), dumps: new Map() };
for (let i = 2; i < process.argv.length; i++) {
  const a = process.argv[i];
  if (a === "--seconds") {
    const v = process.argv[++i];
    if (v === undefined || !(Number(v) > 0)) usage(`--seconds: not a positive number: ${v}`);
    args.seconds = Number(v);
  } else if (a === "--until-topic") {
    const v = process.argv[++i] ?? "";
    // The count follows the last colon: topics may hold colons, counts do not.
    const m = /^(.+):(\d+)$/.exec(v);
    if (!m) usage(`--until-topic: expected TOPIC:N, got ${v}`);
    args.until.set(m[1], Number(m[2]));
  } else if (a === "--dump") {
    const topic = process.argv[++i];
    const file = process.argv[++i];
    if (file === undefined) usage("--dump needs a topic and a file");
    args.dumps.set(topic, { file, fd: undefined });
  } else if (a.startsWith("-")) usage(`unknown option ${a}`);
  else if (args.url !== undefined) usage("one URL only");
  else args.url = a;
}
if (args.url === undefined) usage("no URL");
if (!/^wss?:\/\/[^/]+/.test(args.url)) usage(`not a ws:// URL: ${args.url}`);
for (const d of args.dumps.values()) {
  try {
    d.fd = fs.openSync(d.file, "w");
  } catch (e) {
    usage(`--dump: cannot write ${d.file}: ${e.message}`);
  }
}

const summary = { url: args.url, serverInfo: null, channels: [], messages: {}, bytes: {}, statuses: [], errors: [] };
let errorCount = 0;
const fail = (msg) => {
  if (errorCount++ < 20) summary.errors.push(msg);
};

const { FoxgloveClient } = wsProtocol;
const channels = new Map(); // channel id -> { topic, schemaName, check }
const subscriptions = new Map(); // our subscription id -> channel
const utf8 = new TextDecoder("utf-8", { fatal: true });
let ending = false;
let opened = false;

const client = new FoxgloveClient({ ws: new WebSocket(args.url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]) });

client.on("open", () => {
  opened = true;
});
client.on("error", (e) => fail(`client error: ${e?.message ?? e}`));
client.on("serverInfo", (info) => {
  if (summary.serverInfo) fail("serverInfo sent twice");
  summary.serverInfo = info;
});
client.on("status", (s) => {
  summary.statuses.push({ level: s.level, message: s.message });
  if (s.level === 2) fail(`status level 2: ${s.message}`);
});
client.on("advertise", (list) => {
  for (const c of list) {
    if (channels.has(c.id)) {
      fail(`channel ${c.id} (${c.topic}) advertised twice`);
      continue;
    }
    let check;
    try {
      if (c.encoding !== "json") throw new Error(`encoding "${c.encoding}", expected "json"`);
      if (c.schemaEncoding !== "jsonschema") throw new Error(`schemaEncoding "${c.schemaEncoding}", expected "jsonschema"`);
      check = makeChecker(c.schemaName, c.schema);
    } catch (e) {
      // Still subscribed and counted: a channel that cannot be checked is one error, not one per message.
      fail(`channel ${c.id} (${c.topic}): ${e.message}`);
    }
    channels.set(c.id, { topic: c.topic, schemaName: c.schemaName, check });
    summary.channels.push(c.topic);
    summary.messages[c.topic] ??= 0;
    summary.bytes[c.topic] ??= 0;
    subscriptions.set(client.subscribe(c.id), channels.get(c.id));
  }
});
client.on("unadvertise", (ids) => fail(`unexpected unadvertise of ${JSON.stringify(ids)}`));
client.on("message", ({ subscriptionId, timestamp, data }) => {
  const ch = subscriptions.get(subscriptionId);
  if (!ch) {
    fail(`message for subscription ${subscriptionId}, which is not ours`);
    return;
  }
  const where = `${ch.topic} log_time ${timestamp}`;
  summary.messages[ch.topic]++;
  summary.bytes[ch.topic] += data.byteLength;
  let obj;
  try {
    obj = JSON.parse(utf8.decode(data));
  } catch (e) {
    fail(`${where}: not UTF-8 JSON: ${e.message}`);
    return;
  }
  if (ch.check) for (const p of ch.check(obj)) fail(`${where}: ${p}`);
  const dump = args.dumps.get(ch.topic);
  if (dump) fs.writeSync(dump.fd, JSON.stringify(obj) + "\n");
  if (args.until.size > 0 && [...args.until].every(([t, n]) => (summary.messages[t] ?? 0) >= n)) finish();
});
client.on("close", (ev) => {
  if (ending) return;
  const how = `code ${ev?.code}${ev?.reason ? ` (${ev.reason})` : ""}`;
  fail(opened ? `connection closed by the server before the end: ${how}` : `connection failed before it opened: ${how}`);
  finish();
});

const timer = setTimeout(finish, args.seconds * 1000);

function finish() {
  if (ending) return;
  ending = true;
  clearTimeout(timer);
  for (const [t, n] of args.until) {
    if ((summary.messages[t] ?? 0) < n) fail(`--until-topic ${t}:${n}: ${summary.messages[t] ?? 0} messages in ${args.seconds} s`);
  }
  if (summary.serverInfo === null) fail("no serverInfo");
  if (channels.size === 0) fail("no channel advertised");
  if (errorCount > 20) summary.errors.push(`... and ${errorCount - 20} more`);
  for (const d of args.dumps.values()) fs.closeSync(d.fd);
  try {
    client.close();
  } catch {
    // already closed
  }
  process.stdout.write(JSON.stringify(summary) + "\n");
  process.exit(errorCount > 0 ? 1 : 0);
}

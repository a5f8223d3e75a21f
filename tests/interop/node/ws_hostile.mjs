#!/usr/bin/env node
// Clients that misbehave, against `fieldguard run`'s view server (Foxglove WebSocket protocol). Raw `ws`, not
// FoxgloveClient: a well-behaved library would refuse to send most of this.
//
//   node ws_hostile.mjs ws://HOST:PORT MODE [--seconds S] [--resume-seconds R] [--cycles K] [--topic T]...
//
// MODE:
//   garbage          one connection sends messages the server cannot use, one at a time, and expects exactly
//                    one level-2 status for each (none for the valid ones among them) and the connection to stay
//                    open; a second sends a 70 KB text message (over the server's 64 KiB limit) and expects to be
//                    closed; a third sends 150 bad messages and expects to be closed (kMaxBadMessages 100); a
//                    fourth sends a text frame that is not UTF-8 (closed or a status, either is fine). Last, the
//                    status page must still answer. Exit 0 when all of that holds, 1 otherwise.
//   stall            subscribes to every channel, then stops reading (the TCP socket paused) for S seconds
//                    (default 10) while the daemon goes on; then reads again for R seconds (default 3) and checks
//                    that every frame that arrives is well formed (what the server queued or was writing while
//                    the client stalled), then closes. The status page's frame number before and after the stall
//                    shows the daemon kept deciding. --cycles K repeats stall and read K times on the one
//                    connection (each stall leaves a different write stuck); --topic subscribes to these topics
//                    only (default every channel). Exit 1 when connecting or the advertise failed, or a frame is
//                    malformed; else 0.
//   noproto          upgrades without the subprotocol, then with a wrong one: both must be refused with HTTP 400.
//   flood-connect N  opens N connections at once: how many were accepted, how many refused with 503
//                    (view.server.max_clients). Exit 0 always.
// Prints one JSON line. Exit 2 on a usage error.
import http from "node:http";
import WebSocket from "ws";
import { makeChecker } from "./foxglove_validate.mjs";

const SUBPROTOCOL = "foxglove.websocket.v1";
const USAGE =
  "usage: node ws_hostile.mjs ws://HOST:PORT garbage|stall|noproto|flood-connect N [--seconds S] [--resume-seconds R] [--cycles K] [--topic T]...";
function usage(message) {
  process.stderr.write(`ws_hostile: ${message}\n${USAGE}\n`);
  process.exit(2);
}

const args = { url: undefined, mode: undefined, n: undefined, seconds: 10, resumeSeconds: 3, cycles: 1, topics: [] };
{
  const pos = [];
  for (let i = 2; i < process.argv.length; i++) {
    const a = process.argv[i];
    if (a === "--seconds" || a === "--resume-seconds") {
      const v = process.argv[++i];
      if (v === undefined || !(Number(v) >= 0)) usage(`${a}: not a number: ${v}`);
      if (a === "--seconds") args.seconds = Number(v);
      else args.resumeSeconds = Number(v);
    } else if (a === "--cycles") {
      const v = process.argv[++i];
      if (!/^\d+$/.test(v ?? "") || Number(v) < 1) usage(`--cycles: not a count >= 1: ${v}`);
      args.cycles = Number(v);
    } else if (a === "--topic") {
      const v = process.argv[++i];
      if (v === undefined) usage("--topic needs a topic");
      args.topics.push(v);
    } else if (a.startsWith("--")) usage(`unknown option ${a}`);
    else pos.push(a);
  }
  [args.url, args.mode] = pos;
  if (!args.url || !/^ws:\/\/[^/]+/.test(args.url)) usage(`not a ws:// URL: ${args.url}`);
  if (args.mode === "flood-connect") {
    if (!/^\d+$/.test(pos[2] ?? "") || Number(pos[2]) < 1) usage("flood-connect needs a count N >= 1");
    args.n = Number(pos[2]);
    if (pos.length > 3) usage("too many arguments");
  } else if (["garbage", "stall", "noproto"].includes(args.mode)) {
    if (pos.length > 2) usage("too many arguments");
  } else usage(`unknown mode ${args.mode}`);
}

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

// One connection and everything it received, with a way to wait for a condition on it.
class Conn {
  constructor(url, protocols) {
    this.opened = false;
    this.serverInfo = undefined;
    this.advertise = undefined; // the channels
    this.statuses = [];
    this.texts = 0;
    this.binaries = 0;
    this.closed = undefined; // { code, reason } once closed, by either side
    this.refused = undefined; // { status, body } when the upgrade was answered with anything but 101
    this.error = undefined;
    this.onBinary = undefined;
    this.waiters = new Set();
    // No permessage-deflate: frames on the wire exactly as the server wrote them.
    this.ws = new WebSocket(url, protocols, { perMessageDeflate: false, handshakeTimeout: 10000 });
    this.ws.on("open", () => {
      this.opened = true;
      this.notify();
    });
    this.ws.on("message", (data, isBinary) => {
      if (isBinary) {
        this.binaries++;
        this.onBinary?.(data);
      } else {
        this.texts++;
        let j;
        try {
          j = JSON.parse(data.toString("utf8"));
        } catch {
          j = { op: "<not JSON>", text: data.toString("utf8").slice(0, 200) };
        }
        if (j.op === "status") this.statuses.push(j);
        else if (j.op === "serverInfo") this.serverInfo = j;
        else if (j.op === "advertise") this.advertise = j.channels;
      }
      this.notify();
    });
    this.ws.on("close", (code, reason) => {
      this.closed = { code, reason: reason.toString() };
      this.notify();
    });
    this.ws.on("error", (e) => {
      this.error ??= e.message;
      this.notify();
    });
    // With this listener `ws` leaves a refused upgrade to us: keep the status and body, then drop the socket.
    this.ws.on("unexpected-response", (req, res) => {
      let body = "";
      res.setEncoding("utf8");
      res.on("data", (d) => (body += d));
      res.on("end", () => {
        this.refused = { status: res.statusCode, body: body.trim() };
        this.ws.terminate();
        this.notify();
      });
    });
  }
  notify() {
    for (const w of [...this.waiters]) w();
  }
  // Resolves true as soon as pred() holds, false after ms without it.
  until(pred, ms) {
    if (pred()) return Promise.resolve(true);
    return new Promise((resolve) => {
      const w = () => {
        if (!pred()) return;
        clearTimeout(t);
        this.waiters.delete(w);
        resolve(true);
      };
      const t = setTimeout(() => {
        this.waiters.delete(w);
        resolve(pred());
      }, ms);
      this.waiters.add(w);
    });
  }
  // Open, serverInfo and advertise in; false when any of it did not come.
  ready(ms = 5000) {
    return this.until(() => (this.serverInfo && this.advertise) || this.closed || this.refused, ms).then(
      () => Boolean(this.serverInfo && this.advertise && !this.closed),
    );
  }
  send(data, binary = false) {
    this.ws.send(typeof data === "string" || Buffer.isBuffer(data) ? data : JSON.stringify(data), { binary });
  }
  async close(ms = 2000) {
    if (!this.closed) {
      this.ws.close(1000);
      await this.until(() => this.closed, ms);
      if (!this.closed) this.ws.terminate();
    }
  }
}

// GET on the same port: the status page must keep answering whatever the WebSocket clients do.
function getStatus() {
  const url = args.url.replace(/^ws:/, "http:").replace(/\/*$/, "") + "/status.json";
  return new Promise((resolve) => {
    const req = http.get(url, { timeout: 5000 }, (res) => {
      let body = "";
      res.setEncoding("utf8");
      res.on("data", (d) => (body += d));
      res.on("end", () => {
        let json;
        try {
          json = JSON.parse(body);
        } catch {
          json = undefined;
        }
        resolve({ status: res.statusCode, json });
      });
    });
    req.on("timeout", () => req.destroy(new Error("timeout")));
    req.on("error", (e) => resolve({ status: null, error: e.message }));
  });
}

const print = (o) => process.stdout.write(JSON.stringify(o) + "\n");
const sub = (id, channelId) => ({ op: "subscribe", subscriptions: [{ id, channelId }] });
const unsub = (id) => ({ op: "unsubscribe", subscriptionIds: [id] });

async function garbage() {
  const failures = [];
  const out = { sent: 0, statuses: 0, closed_by_server: false, close_code: null, oversize_closed: false };

  // 1. One bad message at a time, each waited for: the server answers in order, so a status belongs to the
  //    message just sent. expect: how many level-2 statuses it must bring (0 for the valid ones).
  const cases = [
    { name: "non-JSON text", data: "this is not JSON {", expect: 1 },
    { name: "JSON array", data: "[1,2,3]", expect: 1 },
    { name: "op is a number", data: { op: 42 }, expect: 1 },
    { name: "unknown op", data: { op: "nonsense" }, expect: 1 },
    { name: "subscribe to channel 999", data: sub(100, 999), expect: 1 },
    { name: "subscribe with a negative id", data: sub(-1, 1), expect: 1 },
    { name: "subscribe with a string channelId", data: sub(101, "1"), expect: 1 },
    { name: "binary frame (a client MESSAGE_DATA)", data: Buffer.from([1, 1, 0, 0, 0, 0x7b, 0x7d]), binary: true, expect: 1 },
    { name: "unsubscribe an unknown id", data: unsub(12345), expect: 1 },
    { name: "valid subscribe: id 7 to channel 1", data: sub(7, 1), expect: 0 },
    { name: "subscribe with id 7 again", data: sub(7, 1), expect: 1, match: /in use/ },
    // Beyond the obvious: edges of the number checks, and a parser stress.
    { name: "subscribe without subscriptions", data: { op: "subscribe" }, expect: 1 },
    { name: "subscribe to channel 0", data: sub(102, 0), expect: 1 },
    { name: "subscribe with id 2^32", data: sub(2 ** 32, 1), expect: 1 },
    { name: "subscribe with a fractional id", data: sub(1.5, 1), expect: 1 },
    { name: "one subscribe, two bad entries", data: { op: "subscribe", subscriptions: [{ id: 103 }, "x"] }, expect: 2 },
    { name: "unsubscribe id 2^32+7 (7 modulo 2^32)", data: unsub(2 ** 32 + 7), expect: 1 },
    { name: "array nested 30000 deep (60 KB)", data: "[".repeat(30000) + "]".repeat(30000), expect: 1 },
    { name: "unsubscribe id 7 (valid)", data: unsub(7), expect: 0 },
    { name: "unsubscribe id 7 again", data: unsub(7), expect: 1 },
  ];
  const main = new Conn(args.url, [SUBPROTOCOL]);
  if (!(await main.ready())) {
    print({ ...out, failures: [`main connection: not ready: ${JSON.stringify(main.refused ?? main.closed ?? main.error)}`] });
    process.exit(1);
  }
  out.cases = [];
  for (const c of cases) {
    if (main.closed) break;
    const before = main.statuses.length;
    main.send(c.data, c.binary);
    out.sent++;
    // Wait for the statuses expected, then a little longer for any that should not come.
    await main.until(() => main.statuses.length >= before + c.expect || main.closed, 3000);
    await sleep(c.expect === 0 ? 300 : 100);
    const got = main.statuses.slice(before);
    // Binary frames so far: shows when the valid subscription (id 7, channel 1) starts and stops delivering.
    out.cases.push({ name: c.name, expect: c.expect, got: got.map((s) => `${s.level}: ${s.message}`), binary_frames_so_far: main.binaries });
    if (got.length !== c.expect) failures.push(`${c.name}: ${got.length} statuses, expected ${c.expect}`);
    if (got.some((s) => s.level !== 2)) failures.push(`${c.name}: a status of level other than 2`);
    if (c.match && !got.every((s) => c.match.test(s.message))) failures.push(`${c.name}: status does not say ${c.match}`);
  }
  out.statuses = main.statuses.length;
  out.binary_frames_received = main.binaries;
  out.closed_by_server = Boolean(main.closed);
  out.close_code = main.closed?.code ?? null;
  if (main.closed) failures.push(`main connection closed by the server: ${JSON.stringify(main.closed)}`);
  await main.close();

  // 2. Over the server's read_message_max (64 KiB): the server closes (1009 expected).
  const big = new Conn(args.url, [SUBPROTOCOL]);
  if (await big.ready()) {
    big.send(JSON.stringify({ op: "subscribe", subscriptions: [], pad: "x".repeat(70 * 1024) }));
    await big.until(() => big.closed, 5000);
    out.oversize_closed = Boolean(big.closed);
    out.oversize_close_code = big.closed?.code ?? null;
    out.oversize_statuses = big.statuses.length;
    if (!big.closed) failures.push("70 KB message: connection not closed within 5 s");
    await big.close();
  } else failures.push(`oversize connection: not ready: ${JSON.stringify(big.refused ?? big.closed ?? big.error)}`);

  // 3. Past kMaxBadMessages (100) bad messages the server ends the connection.
  const flood = new Conn(args.url, [SUBPROTOCOL]);
  out.bad_flood = { sent: 0, statuses: 0, closed: false, close_code: null };
  if (await flood.ready()) {
    for (let i = 0; i < 150; i++) flood.send({ op: "nonsense", n: i });
    out.bad_flood.sent = 150;
    await flood.until(() => flood.closed, 5000);
    Object.assign(out.bad_flood, { statuses: flood.statuses.length, closed: Boolean(flood.closed), close_code: flood.closed?.code ?? null });
    if (!flood.closed) failures.push("150 bad messages: connection not closed within 5 s");
    if (flood.statuses.length > 100) failures.push(`150 bad messages: ${flood.statuses.length} statuses, more than kMaxBadMessages 100`);
    await flood.close();
  } else failures.push(`bad-flood connection: not ready: ${JSON.stringify(flood.refused ?? flood.closed ?? flood.error)}`);

  // 4. A text frame that is not UTF-8 (RFC 6455 says fail the connection; a status would do too).
  const utf = new Conn(args.url, [SUBPROTOCOL]);
  if (await utf.ready()) {
    utf.send(Buffer.from([0x7b, 0x22, 0x6f, 0x70, 0x22, 0x3a, 0x22, 0xff, 0xfe, 0x22, 0x7d]), false); // {"op":"\xff\xfe"}
    await utf.until(() => utf.closed || utf.statuses.length > 0, 3000);
    out.invalid_utf8 = { closed: Boolean(utf.closed), close_code: utf.closed?.code ?? null, statuses: utf.statuses.map((s) => s.message) };
    if (!utf.closed && utf.statuses.length === 0) failures.push("invalid UTF-8 text frame: neither closed nor answered within 3 s");
    await utf.close();
  } else failures.push(`UTF-8 connection: not ready: ${JSON.stringify(utf.refused ?? utf.closed ?? utf.error)}`);

  // 5. The server is still there.
  const page = await getStatus();
  out.status_page_after = page.status;
  if (page.status !== 200) failures.push(`status page after: ${page.status ?? page.error}`);

  out.failures = failures;
  print(out);
  process.exit(failures.length ? 1 : 0);
}

async function stall() {
  const c = new Conn(args.url, [SUBPROTOCOL]);
  const out = { channels: 0, subscribed: [], stall_s: args.seconds, resume_s: args.resumeSeconds, cycles: args.cycles };
  if (!(await c.ready())) {
    print({ ...out, error: `not ready: ${JSON.stringify(c.refused ?? c.closed ?? c.error)}` });
    process.exit(1);
  }
  // Every frame checked, whenever it is read: opcode, a subscription of ours, a log time that does not go back
  // on its channel, UTF-8 JSON valid against the channel's schema.
  const subs = new Map();
  for (const ch of c.advertise) {
    if (args.topics.length && !args.topics.includes(ch.topic)) continue;
    let check;
    try {
      check = makeChecker(ch.schemaName, ch.schema);
    } catch {
      check = undefined; // ws_client.mjs reports schema setup problems; this one is about framing
    }
    subs.set(ch.id, { topic: ch.topic, check, last: -1n });
  }
  out.channels = c.advertise.length;
  const missing = args.topics.filter((t) => ![...subs.values()].some((s) => s.topic === t));
  if (subs.size === 0 || missing.length) {
    print({ ...out, error: `not advertised: ${missing.join(", ") || "(no channel)"}` });
    process.exit(1);
  }
  const phase = { name: "before", frames: { before: 0, paused: 0, after: 0 }, bytes: { before: 0, paused: 0, after: 0 } };
  const malformed = [];
  const utf8 = new TextDecoder("utf-8", { fatal: true });
  c.onBinary = (buf) => {
    phase.frames[phase.name]++;
    phase.bytes[phase.name] += buf.length;
    const bad = (why) => malformed.push(`${phase.name}: ${why}`);
    if (buf.length < 13) return bad(`frame of ${buf.length} bytes`);
    if (buf[0] !== 1) return bad(`opcode ${buf[0]} (first bytes ${buf.subarray(0, 13).toString("hex")})`);
    const s = subs.get(buf.readUInt32LE(1));
    if (!s) return bad(`subscription id ${buf.readUInt32LE(1)} is not ours (first bytes ${buf.subarray(0, 13).toString("hex")})`);
    const t = buf.readBigUInt64LE(5);
    if (t < s.last) bad(`${s.topic}: log time ${t} after ${s.last}`);
    s.last = t;
    let obj;
    try {
      obj = JSON.parse(utf8.decode(buf.subarray(13)));
    } catch (e) {
      return bad(`${s.topic}: not UTF-8 JSON: ${e.message}`);
    }
    const problems = s.check ? s.check(obj) : [];
    if (problems.length) bad(`${s.topic}: ${problems[0]}`);
  };
  // Subscription id = channel id: a frame's id says its channel.
  c.send({ op: "subscribe", subscriptions: [...subs.keys()].map((id) => ({ id, channelId: id })) });
  out.subscribed = [...subs.values()].map((s) => s.topic);

  const statusBefore = await getStatus();
  for (let cycle = 0; cycle < args.cycles && !c.closed; cycle++) {
    // Stop reading: the kernel's buffers fill, then the server's queue for this client. `ws` resumes its
    // socket itself after back-pressure, so it is paused again until the stall ends.
    phase.name = "paused";
    c.ws._socket.pause();
    const keepPaused = setInterval(() => {
      if (!c.ws._socket.isPaused()) c.ws._socket.pause();
    }, 50);
    await c.until(() => c.closed, args.seconds * 1000);
    clearInterval(keepPaused);
    // Read again: what the server had queued, and the write it had stuck, arrive now.
    phase.name = "after";
    c.ws._socket.resume();
    await c.until(() => c.closed, args.resumeSeconds * 1000);
  }
  const statusAfter = await getStatus();

  out.status_frame_before = statusBefore.json?.frame ?? null;
  out.status_frame_after = statusAfter.json?.frame ?? null;
  out.decided_during_test = out.status_frame_after !== null && out.status_frame_before !== null ? out.status_frame_after - out.status_frame_before : null;
  out.frames = phase.frames;
  out.bytes = phase.bytes;
  out.statuses = c.statuses.map((s) => `${s.level}: ${s.message}`);
  out.closed_by_server = Boolean(c.closed);
  out.close_code = c.closed?.code ?? null;
  out.malformed = malformed.length;
  out.malformed_examples = malformed.slice(0, 10);
  await c.close();
  print(out);
  process.exit(malformed.length ? 1 : 0);
}

async function noproto() {
  const attempts = [];
  for (const offered of [undefined, ["foxglove.websocket.v0"]]) {
    const c = new Conn(args.url, offered);
    await c.until(() => c.opened || c.refused || c.closed, 5000);
    attempts.push({ offered: offered ?? null, accepted: c.opened, status: c.refused?.status ?? null, body: c.refused?.body ?? null, error: c.refused ? undefined : c.error });
    if (c.opened) await c.close();
  }
  const refused = attempts.every((a) => a.status === 400);
  print({ attempts, refused });
  process.exit(refused ? 0 : 1);
}

async function floodConnect() {
  const conns = Array.from({ length: args.n }, () => new Conn(args.url, [SUBPROTOCOL]));
  await Promise.all(conns.map((c) => c.until(() => c.advertise || c.refused || c.closed, 10000)));
  const out = { requested: args.n, accepted: 0, advertised: 0, refused_503: 0, other: 0, other_examples: [], max_clients_said: null };
  for (const c of conns) {
    if (c.opened) out.accepted++;
    if (c.advertise) out.advertised++;
    if (c.refused?.status === 503) {
      out.refused_503++;
      out.max_clients_said ??= Number(/max_clients (\d+)/.exec(c.refused.body)?.[1] ?? NaN);
    } else if (!c.opened) {
      out.other++;
      if (out.other_examples.length < 5) out.other_examples.push(c.refused ?? c.closed ?? c.error ?? "no answer in 10 s");
    }
  }
  // Informational: the server counts a client from its upgrade, so a burst should not pass the limit.
  out.over_limit = out.max_clients_said !== null && out.accepted > out.max_clients_said;
  await Promise.all(conns.map((c) => c.close()));
  print(out);
  process.exit(0);
}

await { garbage, stall, noproto, "flood-connect": floodConnect }[args.mode]();

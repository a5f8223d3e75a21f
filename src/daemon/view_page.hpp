#pragma once
// The status page the view server serves at / (view_server.hpp): for an operator's tablet at the edge of the field.
// The decision first, large and coloured (red STOP with its reason, green GO), then each sensor's state and rate,
// then the newest bird's-eye picture with the boxes and the stop zone. It asks /status.json twice a second and
// the picture once a second; when the daemon stops answering it says so instead of showing the last decision.

namespace fieldguard::app {

inline constexpr const char* kStatusPage = R"html(<!doctype html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>fieldguard</title>
<style>
  body { margin: 0; font-family: sans-serif; background: #111; color: #eee; }
  #decision { padding: 4vh 4vw; font-size: 10vw; font-weight: bold; text-align: center; }
  #decision.stop { background: #c62828; color: #fff; }
  #decision.go { background: #2e7d32; color: #fff; }
  #decision.unknown { background: #555; color: #fff; }
  #reason { font-size: 4vw; font-weight: normal; margin-top: 1vh; }
  main { display: flex; flex-wrap: wrap; gap: 2vw; padding: 2vw; align-items: flex-start; }
  table { border-collapse: collapse; font-size: 2.6vh; }
  td, th { padding: 0.6vh 1.2vw; text-align: left; border-bottom: 1px solid #333; }
  .ok { color: #81c784; } .fault { color: #ff8a80; font-weight: bold; } .off { color: #888; }
  #bev { max-width: 100%; height: 60vh; image-rendering: pixelated; border: 1px solid #333; }
  #detail { font-size: 1.8vh; color: #aaa; padding: 0 2vw 2vh; word-break: break-word; }
</style>
</head>
<body>
<div id="decision" class="unknown">&hellip;<div id="reason">waiting for the daemon</div></div>
<main>
  <table id="sensors"><thead><tr><th>sensor</th><th>state</th><th>rate</th></tr></thead><tbody></tbody></table>
  <img id="bev" alt="bird's-eye view: no picture yet">
</main>
<div id="detail"></div>
<script>
"use strict";
const decision = document.getElementById("decision");
const reason = document.getElementById("reason");
function show(s) {
  decision.className = s.stop ? "stop" : "go";
  decision.firstChild.textContent = s.stop ? "STOP" : "GO";
  reason.textContent = s.headline.replace(/^(STOP|GO) ?/, "") || (s.stop ? "" : "path clear");
  const body = document.querySelector("#sensors tbody");
  body.replaceChildren(...s.sensors.map((x) => {
    const tr = document.createElement("tr");
    const cls = x.state === "ok" ? "ok" : x.state === "off" ? "off" : "fault";
    for (const [text, c] of [[x.name, ""], [x.state, cls], [x.state === "off" ? "" : x.rate_hz.toFixed(1) + " Hz", ""]]) {
      const td = document.createElement("td");
      td.textContent = text;
      if (c) td.className = c;
      tr.appendChild(td);
    }
    return tr;
  }));
  document.getElementById("detail").textContent = "frame " + s.frame + " | " + s.status;
}
async function poll() {
  try {
    const r = await fetch("status.json", { cache: "no-store" });
    if (!r.ok) throw new Error(r.status);
    const s = await r.json();
    if (s.headline !== undefined) show(s);
  } catch (e) {
    decision.className = "unknown";
    decision.firstChild.textContent = "NO DATA";
    reason.textContent = "the daemon does not answer";
  }
}
function picture() { document.getElementById("bev").src = "bev.png?t=" + Date.now(); }
poll(); picture();
setInterval(poll, 500);
setInterval(picture, 1000);
</script>
</body>
</html>
)html";

}  // namespace fieldguard::app

#include "view_page.h"

namespace tilth::view {

// The page keeps what it received in window.tilthView (images, samples, status, errors),
// which the tests read.
std::string_view page_html() {
  return R"html(<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>Tilth live view</title>
<style>
  body { margin: 0; background: #111; color: #ddd; font: 15px system-ui, sans-serif; }
  header { display: flex; flex-wrap: wrap; gap: 6px 22px; align-items: baseline; padding: 8px 12px; background: #1c1c1c; }
  #distance { font-size: 32px; font-weight: 600; }
  .valid { color: #5e5; } .held { color: #fb3; } .invalid { color: #f55; } .stale { color: #888; }
  main { display: flex; flex-wrap: wrap; gap: 10px; padding: 10px; }
  #frame { flex: 2 1 520px; max-width: 100%; }
  #frame canvas { width: 100%; height: auto; background: #222; display: block; }
  aside { flex: 1 1 300px; }
  #plot { width: 100%; height: 220px; background: #1a1a1a; display: block; }
  table { border-collapse: collapse; width: 100%; margin-top: 8px; font-size: 13px; }
  td, th { padding: 2px 6px; text-align: right; } td:first-child, th:first-child { text-align: left; }
  tr:nth-child(even) { background: #1a1a1a; }
  .note { color: #999; font-size: 13px; }
</style>
</head>
<body>
<header>
  <span id="distance" class="stale">–</span>
  <span>soil <b id="soil">–</b></span>
  <span>graph <b id="fps">–</b></span>
  <span>cameras <b id="cameras">–</b></span>
  <span class="note" id="link">connecting…</span>
</header>
<main>
  <section id="frame"><canvas id="image" width="640" height="480"></canvas></section>
  <aside>
    <canvas id="plot" width="600" height="220"></canvas>
    <div class="note">distance over the last minute: green valid, amber held, red marks invalid frames</div>
    <table id="stages"><thead><tr><th>stage</th><th>p50 ms</th><th>p99 ms</th><th>errors</th></tr></thead><tbody></tbody></table>
  </aside>
</main>
<script>
"use strict";
const view = window.tilthView = { images: 0, samples: 0, statuses: 0, errors: [], plotted: 0 };
window.addEventListener("error", e => view.errors.push(String(e.message)));
const $ = id => document.getElementById(id);
const samples = [];
const kSpanS = 60;

function showLatest(s) {
  const d = $("distance");
  if (s.valid) {
    d.textContent = s.mm.toFixed(1) + " mm" + (s.held ? " held" : "");
    d.className = s.held ? "held" : "valid";
  } else {
    d.textContent = "invalid: " + s.cause.replace(/_/g, " ");
    d.className = "invalid";
  }
  $("soil").textContent = (100 * s.soil).toFixed(0) + " %";
}

function drawPlot() {
  const c = $("plot"), g = c.getContext("2d");
  const w = c.width = c.clientWidth || 600, h = c.height;
  g.clearRect(0, 0, w, h);
  if (samples.length === 0) return;
  const now = samples[samples.length - 1].t;
  const shown = samples.filter(s => s.t >= now - kSpanS);
  const valid = shown.filter(s => s.valid);
  let lo = Math.min(...valid.map(s => s.mm)), hi = Math.max(...valid.map(s => s.mm));
  if (!isFinite(lo)) { lo = 0; hi = 1; }
  const pad = Math.max(2, 0.1 * (hi - lo)); lo -= pad; hi += pad;
  const x = t => 40 + (w - 50) * (1 - (now - t) / kSpanS);
  const y = mm => 10 + (h - 40) * (hi - mm) / (hi - lo);
  g.fillStyle = "#888"; g.font = "11px sans-serif";
  g.fillText(hi.toFixed(0) + " mm", 2, 14); g.fillText(lo.toFixed(0) + " mm", 2, h - 32);
  g.fillText("-" + kSpanS + " s", 40, h - 4); g.fillText("now", w - 30, h - 4);
  for (const s of shown) {
    if (s.valid) { g.fillStyle = s.held ? "#fb3" : "#5e5"; g.fillRect(x(s.t) - 1, y(s.mm) - 1, 3, 3); }
    else { g.fillStyle = "#f55"; g.fillRect(x(s.t) - 1, h - 24, 3, 8); }
  }
  view.plotted += 1;
}

function onSamples(batch) {
  for (const s of batch.samples) samples.push(s);
  const now = samples.length ? samples[samples.length - 1].t : 0;
  while (samples.length && samples[0].t < now - kSpanS) samples.shift();
  view.samples += batch.samples.length;
  view.lastSamples = samples.slice(-20);
  if (batch.samples.length) showLatest(batch.samples[batch.samples.length - 1]);
}

function onStatus(status) {
  view.statuses += 1;
  view.status = status;
  $("fps").textContent = status.frames_per_second.toFixed(1) + " frames/s, " +
      status.frames_dropped + " dropped";
  const cams = status.cameras;
  $("cameras").textContent = !cams ? "not connected" :
      (cams.streaming ? "streaming" : "down: " + cams.problem) +
      " (" + cams.completed + " frames, " + cams.lost + " lost)";
  $("cameras").className = !cams || cams.streaming ? "" : "invalid";
  const body = $("stages").tBodies[0];
  body.replaceChildren(...status.stages.map(s => {
    const row = document.createElement("tr");
    for (const v of [s.node, s.p50_ms.toFixed(2), s.p99_ms.toFixed(2), s.errors]) {
      const cell = document.createElement("td"); cell.textContent = v; row.appendChild(cell);
    }
    return row;
  }));
}

function connectEvents() {
  const events = new EventSource("events");
  events.addEventListener("samples", e => onSamples(JSON.parse(e.data)));
  events.addEventListener("status", e => onStatus(JSON.parse(e.data)));
  events.onopen = () => { $("link").textContent = "live"; };
  events.onerror = () => { $("link").textContent = "reconnecting…"; };
}

async function pullImages() {
  let generation = 0;
  const canvas = $("image"), g = canvas.getContext("2d");
  for (;;) {
    try {
      const reply = await fetch("frame.jpg?after=" + generation, { cache: "no-store" });
      if (reply.status === 200) {
        generation = Number(reply.headers.get("X-Generation"));
        const bitmap = await createImageBitmap(await reply.blob());
        if (canvas.width !== bitmap.width) { canvas.width = bitmap.width; canvas.height = bitmap.height; }
        g.drawImage(bitmap, 0, 0);
        bitmap.close();
        view.images += 1;
        view.frameId = Number(reply.headers.get("X-Frame-Id"));
      } else if (reply.status !== 204) {
        await new Promise(r => setTimeout(r, 1000));
      }
    } catch (e) {
      await new Promise(r => setTimeout(r, 1000));
    }
  }
}

connectEvents();
pullImages();
setInterval(drawPlot, 500);
</script>
</body>
</html>
)html";
}

}  // namespace tilth::view

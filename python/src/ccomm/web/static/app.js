// SPDX-License-Identifier: Apache-2.0
// ccomm live view: a small Foxglove WebSocket protocol client (the same server Foxglove
// connects to), a status table and one uPlot chart per plotted signal.
"use strict";

// The same protocol under its two names: foxglove-sdk servers take the first, older ones
// (foxglove_bridge 0.8, the ws-protocol reference servers) the second.
const SUBPROTOCOLS = ["foxglove.sdk.v1", "foxglove.websocket.v1"];
const OP_MESSAGE_DATA = 1, OP_TIME = 2;     // binary opcodes of the protocol
const SILENT_MS = 3000;                      // no message for this long: "no update"
const MAX_POINTS = 5000;                     // per chart; older points fall off first
const params = new URLSearchParams(location.search);
const windowSeconds = Number(params.get("window")) || 30;

const view = {           // also what the browser test inspects
  config: null, connected: false, rows: {}, charts: {}, received: 0, connections: 0,
  plot: new Set(),
};
window.ccommView = view;

const $ = (sel) => document.querySelector(sel);

function showError(text) {
  const e = $("#error");
  e.textContent = text;
  e.hidden = !text;
}

function setConn(state) {
  const c = $("#conn");
  c.className = "conn " + state;
  c.textContent = state;
  view.connected = state === "connected";
}

// Six significant digits, trailing zeros of the fraction dropped: 1.5e-10 -> "1.5e-10",
// 0.1 -> "0.1", 200000.1 -> "200000". Only the mantissa's fraction is trimmed (trimming
// the whole text turned 1.5e-10 into "1.50000e-1" and 200000.1 into "2").
function formatNumber(v) {
  const [mantissa, exponent] = v.toPrecision(6).split("e");
  const m = mantissa.includes(".") ? mantissa.replace(/\.?0+$/, "") : mantissa;
  return exponent === undefined ? m : m + "e" + exponent;
}

// int64 values come as decimal strings (exact beyond 2^53): shown as they are.
function formatValue(v) {
  if (v === null || v === undefined) return "–";
  if (Array.isArray(v)) return "[" + v.map(formatValue).join(", ") + "]";
  if (typeof v === "number" && !Number.isInteger(v)) return formatNumber(v);
  return String(v);
}
view.formatValue = formatValue;

function formatAge(ns) {
  if (ns === null || ns === undefined) return "–";
  const ms = ns / 1e6;
  return ms < 1000 ? ms.toFixed(1) + " ms" : (ms / 1000).toFixed(1) + " s";
}

function formatError(ns) {
  if (ns < 1000) return ns + " ns";
  if (ns < 1e6) return (ns / 1e3).toFixed(1) + " µs";
  return formatAge(ns);
}

// The age column: the production age (since the producer wrote the value, on the boards'
// common time base) with +/- its error bound when known; otherwise the local age (since
// the value reached this node) marked "local", the reason in the tooltip.
function ageCell(m) {
  if (m.production_age_ns !== null && m.production_age_ns !== undefined)
    return { text: formatAge(m.production_age_ns) + " ±" + formatError(m.production_error_ns), local: false,
             title: "production age (" + m.age_code + "): since the producer wrote the value, within ±" +
                    formatError(m.production_error_ns) };
  if (m.age_ns === null || m.age_ns === undefined) return { text: "–", local: false, title: "" };
  return { text: formatAge(m.age_ns) + " local", local: true,
           title: "local age, since the value reached this node: the production age is unknown (" +
                  (m.age_code || "no_summary") + ")" };
}
view.ageCell = ageCell;

// ---- table ---------------------------------------------------------------------------

function buildTable(cfg) {
  const body = $("#signals tbody");
  body.textContent = "";
  for (const s of cfg.signals) {
    const tr = document.createElement("tr");
    tr.dataset.signal = s.name;
    const type = s.type + (s.count !== 1 ? "[" + s.count + "]" : "") + (s.event ? " event" : "");
    tr.innerHTML = '<td><input type="checkbox"></td><td class="name"></td><td class="type"></td>' +
      '<td><span class="badge never status">never</span></td><td class="value num">–</td>' +
      '<td class="seq num">–</td><td class="age num">–</td><td class="lost num">0</td><td class="skipped num">0</td><td class="msgs num">0</td>';
    tr.querySelector(".name").textContent = s.name;
    tr.querySelector(".type").textContent = type;
    const box = tr.querySelector("input");
    box.checked = view.plot.has(s.name);
    box.addEventListener("change", () => {
      if (box.checked) view.plot.add(s.name); else view.plot.delete(s.name);
      buildCharts();
    });
    body.appendChild(tr);
    view.rows[s.name] = { tr, signal: s, last: null, lastAt: 0, msgs: 0, skipped: 0 };
  }
}

function updateRow(row) {
  const m = row.last, tr = row.tr;
  const silent = row.lastAt > 0 && performance.now() - row.lastAt > SILENT_MS;
  const status = silent ? "silent" : (m ? m.status : "never");
  const badge = tr.querySelector(".status");
  badge.className = "badge status " + status;
  badge.textContent = silent ? "no update" : status;
  tr.dataset.status = status;
  if (!m) return;
  tr.querySelector(".value").textContent = formatValue(m.value);
  tr.querySelector(".seq").textContent = String(m.seq);
  const age = ageCell(m), ageTd = tr.querySelector(".age");
  ageTd.textContent = age.text;
  ageTd.title = age.title;
  ageTd.classList.toggle("local", age.local);
  const lost = tr.querySelector(".lost");
  lost.textContent = String(m.lost);
  lost.classList.toggle("nonzero", m.lost > 0);
  tr.querySelector(".skipped").textContent = String(row.skipped);
  tr.querySelector(".msgs").textContent = String(row.msgs);
}

// ---- charts --------------------------------------------------------------------------

const PALETTE = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#17becf", "#8c564b", "#e377c2"];

function seriesCount(s) { return Math.min(s.count, 8); }

// The y axis is as wide as its widest label needs (a fixed width cut 7+ digit labels),
// measured with the axis's own font; uPlot calls this again while the labels settle.
function yAxisSize(u, values, axisIdx, cycleNum) {
  const axis = u.axes[axisIdx];
  if (cycleNum > 1) return axis._size;  // uPlot's convention: keep the width it converged on
  let size = axis.ticks.size + axis.gap;
  const longest = (values || []).reduce((a, v) => (String(v).length > a.length ? String(v) : a), "");
  if (longest) {
    u.ctx.font = axis.font[0];
    size += u.ctx.measureText(longest).width / devicePixelRatio;
  }
  return Math.ceil(size) + 4;
}

function buildCharts() {
  const box = $("#charts");
  for (const c of Object.values(view.charts)) c.plot && c.plot.destroy();
  box.textContent = "";
  view.charts = {};
  if (typeof uPlot === "undefined") {
    showError("uPlot is not installed on the server (ccomm-web --help, Assets): no plots, the table still works.");
    return;
  }
  for (const name of view.plot) {
    const row = view.rows[name];
    if (!row) continue;
    const s = row.signal, n = seriesCount(s);
    const div = document.createElement("div");
    div.className = "chart";
    div.dataset.signal = name;
    div.innerHTML = '<h2><span class="title"></span><span class="badge never status">never</span></h2>';
    div.querySelector(".title").textContent = name;
    box.appendChild(div);
    const series = [{ label: "time" }];
    for (let i = 0; i < n; i++) {
      const line = { label: s.count === 1 ? "value" : name + "[" + i + "]", stroke: PALETTE[i % PALETTE.length],
                     width: 1.5, points: { show: false } };
      if (s.event) Object.assign(line, { paths: () => null, points: { show: true, size: 7, fill: line.stroke } });
      series.push(line);  // events are points: nothing happened between two of them
    }
    // A scalar state signal gets a second, thick amber series that holds the value only
    // while it is stale: a stale stretch stands out in the plot itself.
    const staleSeries = s.count === 1 && !s.event;
    if (staleSeries) series.push({ label: "stale", stroke: "#d68910", width: 4, points: { show: false }, spanGaps: false });
    const data = [[]];
    for (let i = 1; i < series.length; i++) data.push([]);
    const plot = new uPlot({ width: Math.max(420, div.clientWidth - 8), height: 220, series,
      scales: { x: { time: true } }, axes: [{}, { size: yAxisSize }], legend: { show: s.count !== 1 },
      cursor: { show: true } }, data, div);
    view.charts[name] = { div, plot, data, dirty: true, points: 0, staleSeries };
  }
}

function addPoint(name, tSeconds, value, status) {
  const c = view.charts[name];
  if (!c) return;
  // bool as 0/1; an int64's decimal string as the nearest double (a plot needs no more)
  const values = (Array.isArray(value) ? value : [value]).map((v) =>
    (typeof v === "boolean" || typeof v === "string" ? Number(v) : v));
  c.data[0].push(tSeconds);
  const nValues = c.data.length - 1 - (c.staleSeries ? 1 : 0);
  for (let i = 1; i <= nValues; i++) c.data[i].push(values[i - 1] === undefined ? null : values[i - 1]);
  if (c.staleSeries) {
    const col = c.data[nValues + 1];
    // the fresh point before a stale one starts the amber stretch, so it has a length
    if (status === "stale" && col.length && col[col.length - 1] === null) col[col.length - 1] = c.data[1][col.length - 1];
    col.push(status === "stale" ? values[0] : null);
  }
  const cut = tSeconds - windowSeconds;
  let drop = 0;
  while (drop < c.data[0].length && (c.data[0][drop] < cut || c.data[0].length - drop > MAX_POINTS)) drop++;
  if (drop) for (const col of c.data) col.splice(0, drop);
  c.points++;
  c.dirty = true;
}

function redraw() {
  for (const [name, c] of Object.entries(view.charts)) {
    const row = view.rows[name];
    const badge = c.div.querySelector(".status");
    const status = row.tr.dataset.status || "never";
    badge.className = "badge status " + status;
    badge.textContent = status === "silent" ? "no update" : status;
    if (!c.dirty) continue;
    c.plot.setData(c.data);
    c.dirty = false;
    const col = c.data[1];
    c.div.dataset.points = String(c.data[0].length);
    c.div.dataset.last = col.length ? String(col[col.length - 1]) : "";
  }
}

// ---- protocol client -----------------------------------------------------------------

let ws = null, retryMs = 500;
const channels = new Map();      // channel id -> signal name
const subscriptions = new Map(); // subscription id -> signal name
let nextSubId = 1;
const topicToName = new Map();   // filled from /config.json
const statuses = new Map();      // the server's warnings by id (e.g. ccommd stopped)

function connect() {
  const url = "ws://" + location.hostname + ":" + view.config.ws_port;
  setConn("connecting");
  ws = new WebSocket(url, SUBPROTOCOLS);
  ws.binaryType = "arraybuffer";
  ws.onopen = () => { setConn("connected"); retryMs = 500; view.connections++; statuses.clear(); showError(""); };
  ws.onclose = () => {
    setConn("disconnected");
    channels.clear();
    subscriptions.clear();
    setTimeout(connect, retryMs);   // the server restarted or the network blinked: try again
    retryMs = Math.min(retryMs * 2, 5000);
  };
  ws.onerror = () => showError("cannot reach the Foxglove WebSocket server at " + url + "; retrying");
  ws.onmessage = (ev) => (typeof ev.data === "string" ? onText(ev.data) : onBinary(ev.data));
}

function onText(text) {
  let msg;
  try { msg = JSON.parse(text); } catch (e) { showError("bad message from server: " + e); return; }
  if (msg.op === "advertise") {
    const subs = [];
    for (const ch of msg.channels) {
      const name = topicToName.get(ch.topic);
      if (!name || ch.encoding !== "json") continue;
      channels.set(ch.id, name);
      const id = nextSubId++;
      subscriptions.set(id, name);
      subs.push({ id, channelId: ch.id });
    }
    if (subs.length) ws.send(JSON.stringify({ op: "subscribe", subscriptions: subs }));
  } else if (msg.op === "unadvertise") {
    for (const id of msg.channelIds) channels.delete(id);
  } else if (msg.op === "status" && msg.level >= 1) {
    statuses.set(msg.id || "", msg.message);
    showError([...statuses.values()].join("; "));
  } else if (msg.op === "removeStatus") {
    for (const id of msg.statusIds) statuses.delete(id);
    showError([...statuses.values()].join("; "));
  }
}

const decoder = new TextDecoder();

function onBinary(buf) {
  const dv = new DataView(buf);
  const op = dv.getUint8(0);
  if (op === OP_TIME) {
    const t = Number(dv.getBigUint64(1, true)) / 1e9;
    $("#clock").textContent = new Date(t * 1000).toISOString().slice(11, 23);
    return;
  }
  if (op !== OP_MESSAGE_DATA) return;
  const name = subscriptions.get(dv.getUint32(1, true));
  if (!name) return;
  const t = Number(dv.getBigUint64(5, true)) / 1e9;
  let m;
  try { m = JSON.parse(decoder.decode(new Uint8Array(buf, 13))); } catch (e) { return; }
  show(name, t, m);
}

function show(name, t, m) {
  const row = view.rows[name];
  row.last = m;
  row.lastAt = performance.now();
  row.msgs++;
  row.skipped += m.gap || 0;
  view.received++;
  if (m.status !== "never") addPoint(name, t, m.value, m.status);
  row.dirtyRow = true;
}

function tick() {   // ~10 Hz: the table and the charts follow without redrawing per message
  for (const row of Object.values(view.rows)) {
    if (row.dirtyRow || row.lastAt) { updateRow(row); row.dirtyRow = false; }
  }
  redraw();
}

// What each signal showed before this page opened: an event signal is published once per
// event, so without this a page opened after the last event would say "never".
async function loadLast() {
  let last;
  try {
    last = await (await fetch("/last.json", { cache: "no-store" })).json();
  } catch (e) {
    return;  // an older server: the protocol alone fills the rows
  }
  for (const [name, { log_time_ns: t, message: m }] of Object.entries(last)) {
    if (view.rows[name] && !view.rows[name].last) show(name, t / 1e9, m);
  }
}

async function start() {
  try {
    const r = await fetch("/config.json", { cache: "no-store" });
    view.config = await r.json();
  } catch (e) {
    showError("cannot load /config.json from the ccomm-web server: " + e);
    setConn("disconnected");
    return;
  }
  $("#node").textContent = "node " + view.config.node;
  for (const sig of view.config.signals) topicToName.set(sig.topic, sig.name);
  const chosen = params.get("plot");
  for (const n of chosen !== null ? chosen.split(",").filter(Boolean) : view.config.plot) view.plot.add(n);
  buildTable(view.config);
  buildCharts();
  connect();
  loadLast();
  setInterval(tick, 100);
}

start();

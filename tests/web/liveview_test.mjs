// SPDX-License-Identifier: Apache-2.0
// End-to-end test of ccomm-web: Foxglove's own protocol client (foxglove_probe.mjs) and the
// page in real headless Chromium (playwright-core, the Debian chromium), against a running
// ccommd and ccomm-web that tests/web/run started. Prints TAP and a "N passed, N failed" line.
// Environment: WEB_URL, WS_URL, CCOMM (the ccomm CLI), CCOMM_NODE, PYTHON, WRITER,
// CHROMIUM, SCREENSHOT (where the screenshot goes).
import { execFileSync, spawn } from "node:child_process";
import { readFileSync } from "node:fs";
import net from "node:net";
import { chromium } from "playwright-core";
import WebSocket from "ws";
import { FoxgloveProbe } from "./foxglove_probe.mjs";

const env = (k) => { if (!process.env[k]) throw new Error("missing environment " + k); return process.env[k]; };
const WEB_URL = env("WEB_URL"), WS_URL = env("WS_URL"), NODE = env("CCOMM_NODE");
// 12 s of tick = 1..1200 at 100 Hz: at the default --max-rate a 100 Hz signal must arrive
// within the documented lag (issue 39: the passes locked onto its writes, p50 5.2 ms)
const WRITER_RATE = 100, WRITER_COUNT = 1200;
// docs/integrations/liveview.md: 1-2 ms behind the node on an idle machine. The check is
// for the defect (passes locked onto the writes out of phase: p50 5.2-5.6 ms, half the
// write period), with room for a loaded CI machine (2.20 ms measured in a fresh-clone run
// beside QEMU boards): a timing figure is the benchmark's to claim, not this test's.
const LAG_P50_MS = 4;

let passed = 0, failed = 0, n = 0;
async function check(name, fn) {
  n++;
  try {
    await fn();
    passed++;
    console.log(`ok ${n} - ${name}`);
  } catch (e) {
    failed++;
    console.log(`not ok ${n} - ${name}\n  # ${String(e && e.stack || e).split("\n").join("\n  # ")}`);
  }
}
function assert(cond, what) { if (!cond) throw new Error(what); }
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
async function until(fn, timeoutMs, what) {
  const deadline = Date.now() + timeoutMs;
  let last;
  while (Date.now() < deadline) {
    last = await fn();
    if (last) return last;
    await sleep(50);
  }
  throw new Error(`timed out after ${timeoutMs} ms waiting for ${what}`);
}
const pub = (signal, ...values) => execFileSync(env("CCOMM"), ["--node", NODE, "pub", signal, ...values.map(String)]);
const stats = async () => (await fetch(new URL("/stats.json", WEB_URL))).json();

const LAUNCH = {
  executablePath: env("CHROMIUM"), headless: true,
  // playwright adds --headless and a new empty --user-data-dir itself
  args: ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run", "--disable-background-networking",
         "--disable-component-update", "--disable-sync"],
};

async function openPage(browser, requests, query = "") {
  const page = await browser.newPage({ viewport: { width: 1280, height: 900 } });
  page.on("request", (r) => requests.push(r.url()));
  page.on("pageerror", (e) => console.log("  # page error: " + e));
  const resp = await page.goto(WEB_URL + query, { waitUntil: "load" });
  assert(resp.ok(), "GET / answered " + resp.status());
  return page;
}
const domRow = (page, signal) => page.evaluate((s) => {
  const tr = document.querySelector(`#signals tr[data-signal="${s}"]`);
  if (!tr) return null;
  const chart = document.querySelector(`.chart[data-signal="${s}"]`);
  const c = window.ccommView.charts[s];
  return { status: tr.querySelector(".status").textContent, value: tr.querySelector(".value").textContent,
           seq: tr.querySelector(".seq").textContent, lost: tr.querySelector(".lost").textContent,
           skipped: tr.querySelector(".skipped").textContent,
           chartLast: chart ? chart.dataset.last : null, chartPoints: chart ? Number(chart.dataset.points || 0) : 0,
           plotted: c ? c.plot.data[1].slice(-1)[0] : undefined, series: c ? c.plot.series.length - 1 : 0 };
}, signal);
const canvasPixels = (page, signal) => page.evaluate((s) =>
  document.querySelector(`.chart[data-signal="${s}"] canvas`).toDataURL(), signal);

const probe = new FoxgloveProbe(WS_URL);
let browser, page, browser2, page2;
const requests = [];
const topics = ["wheel_pos", "tick", "drive_ok", "joint_pos", "count64", "unused_sp", "mode_request"];  // topic = signal name

await check("protocol client: every signal advertised as a JSON channel with a jsonschema", async () => {
  await probe.connect();
  assert(probe.serverInfo && probe.serverInfo.name.includes(NODE), "serverInfo names the node: " + JSON.stringify(probe.serverInfo));
  for (const t of topics) {
    const ch = probe.channels.get(t);
    assert(ch, "advertised: " + t);
    assert(ch.encoding === "json" && ch.schemaEncoding === "jsonschema", t + ": " + ch.encoding + "/" + ch.schemaEncoding);
    const schema = JSON.parse(ch.schema);
    // the fields of a `ccomm record` recording, plus age_ns and production_age_ns
    for (const f of ["value", "seq", "source_time_ns", "receive_time_ns", "age_ns", "status", "fresh", "safe_value", "lost", "gap",
                     "production_time_ns", "production_error_ns", "age_code", "production_age_ns"]) {
      assert(schema.properties[f] && schema.required.includes(f), t + " schema lacks " + f);
    }
  }
  const joint = JSON.parse(probe.channels.get("joint_pos").schema).properties.value;
  assert(joint.type === "array" && joint.maxItems === 3 && joint.items.type[0] === "number", "joint_pos value schema " + JSON.stringify(joint));
  assert(JSON.parse(probe.channels.get("tick").schema).properties.value.type[0] === "integer", "tick is integer");
  assert(probe.channels.get("joint_pos").schemaName === "ccomm.double[3]", "schema name " + probe.channels.get("joint_pos").schemaName);
  for (const t of topics) probe.subscribe(t);
});

await check("protocol client: a never-written signal decodes as status never, seq 0, age null", async () => {
  const m = await probe.waitFor("unused_sp", () => true, 3000, "any message");
  assert(m.status === "never" && m.seq === 0 && m.age_ns === null && m.receive_time_ns === null && m.lost === 0 &&
         m.fresh === false && m.gap === 0, JSON.stringify(m));
});

for (const offered of [["foxglove.websocket.v1"], ["foxglove.sdk.v1"]]) {
  await check(`a client offering only ${offered[0]} is accepted, answered with that name, and served`, async () => {
    const old = new FoxgloveProbe(WS_URL, offered);
    try {
      await old.connect();
      assert(old.ws.protocol === offered[0], "server chose " + JSON.stringify(old.ws.protocol));
      old.subscribe("tick");
      await old.waitFor("tick", () => true, 3000, "any message (keepalive within 1 s)");
      assert(old.errors.length === 0, old.errors.join("; "));
    } finally {
      old.close();
    }
  });
}

await check("page loads in headless Chromium, from the server only (no other origin)", async () => {
  browser = await chromium.launch(LAUNCH);
  page = await openPage(browser, requests);
  assert(await page.evaluate(() => typeof uPlot === "function"), "uPlot loaded from /vendor");
  const origin = new URL(WEB_URL).origin;
  const foreign = requests.filter((u) => !u.startsWith(origin) && !u.startsWith(WS_URL));
  assert(foreign.length === 0, "requests elsewhere: " + foreign.join(" "));
});

await check("page connects over the Foxglove protocol, lists every signal, plots the ticked ones", async () => {
  await until(() => page.evaluate(() => document.querySelector("#conn").textContent === "connected"), 10000, "#conn connected");
  const rows = await page.evaluate(() => [...document.querySelectorAll("#signals tbody tr")].map((tr) => tr.dataset.signal));
  assert(rows.length === 7, "rows: " + rows);
  const charts = () => page.evaluate(() => [...document.querySelectorAll(".chart")].map((c) => c.dataset.signal).join(","));
  assert((await charts()) === rows.join(","), "charts at first (--plot default: all 7): " + (await charts()));
  await page.click('#signals tr[data-signal="tick"] input');  // untick: its plot goes
  assert(!(await charts()).split(",").includes("tick"), "tick still plotted: " + (await charts()));
  await page.click('#signals tr[data-signal="tick"] input');
  assert((await charts()).split(",").includes("tick"), "tick not plotted again: " + (await charts()));
  await until(async () => (await domRow(page, "unused_sp")).status === "never", 3000, "unused_sp never");
});

await check("the plot follows a value written with ccomm pub (DOM, plot data and pixels)", async () => {
  pub("wheel_pos", 1.25);
  await until(async () => { const r = await domRow(page, "wheel_pos"); return r.value === "1.25" && r.plotted === 1.25; },
    5000, "wheel_pos 1.25 in table and plot");
  await probe.waitFor("wheel_pos", (m) => m.value === 1.25 && m.status === "fresh", 3000, "1.25 fresh");
  await sleep(300);
  const before = await canvasPixels(page, "wheel_pos");
  pub("wheel_pos", -2.5);
  const r = await until(async () => { const r = await domRow(page, "wheel_pos"); return r.value === "-2.5" && r.chartLast === "-2.5" && r; },
    5000, "wheel_pos -2.5 in table and plot");
  assert(r.chartPoints >= 2, "points " + r.chartPoints);
  await sleep(200);
  assert((await canvasPixels(page, "wheel_pos")) !== before, "the chart's pixels did not change");
  const m = await probe.waitFor("wheel_pos", (m) => m.value === -2.5, 3000, "value -2.5");
  assert(m.status === "fresh" && m.seq >= 2, JSON.stringify(m));
});

await check("the age column: production age ± its error when known (a value of this node: ±0 ns), else the local age marked local", async () => {
  const m = await probe.waitFor("wheel_pos", (m) => m.value === -2.5, 3000, "value -2.5");
  assert(m.age_code === "same_node" && m.production_error_ns === 0 && m.production_age_ns >= 0 &&
         Math.abs(m.production_time_ns - (Date.now() * 1e6 - m.production_age_ns)) < 5e9, JSON.stringify(m));
  const cell = () => page.evaluate(() => { const td = document.querySelector('#signals tr[data-signal="wheel_pos"] .age');
    return { text: td.textContent, local: td.classList.contains("local"), title: td.title }; });
  const c = await until(async () => { const c = await cell(); return / ±0 ns$/.test(c.text) && c; }, 3000, "wheel_pos age ±0 ns");
  assert(!c.local && c.title.includes("production age (same_node)"), JSON.stringify(c));
  // The cases a one-node page cannot produce, through the page's own formatting.
  const local = await page.evaluate(() => window.ccommView.ageCell(
    { age_ns: 1.25e6, production_age_ns: null, production_error_ns: null, age_code: "local_unsynced" }));
  assert(local.text === "1.3 ms local" && local.local && local.title.includes("local_unsynced"), JSON.stringify(local));
  const synced = await page.evaluate(() => window.ccommView.ageCell(
    { age_ns: 1e6, production_age_ns: 41.2e6, production_error_ns: 2000, age_code: "synced" }));
  assert(synced.text === "41.2 ms ±2.0 µs" && !synced.local, JSON.stringify(synced));
});

await check("numbers as the page shows them: 6 significant digits, the exponent whole (1.5e-10 was 1.50000e-1)", async () => {
  const shown = await page.evaluate(() => [1.5e-10, 1e-100, 1.5e300, 200000.1, 0.1, 3.14159265, -2.5, 1.0000001e-7, 7]
    .map((v) => window.ccommView.formatValue(v)));
  const want = ["1.5e-10", "1e-100", "1.5e+300", "200000", "0.1", "3.14159", "-2.5", "1e-7", "7"];
  assert(JSON.stringify(shown) === JSON.stringify(want), "formatValue: " + JSON.stringify(shown) + " != " + JSON.stringify(want));
  pub("wheel_pos", 1.5e-10);
  await until(async () => (await domRow(page, "wheel_pos")).value === "1.5e-10", 5000, "wheel_pos 1.5e-10 in the table");
  pub("wheel_pos", -2.5);
  await until(async () => (await domRow(page, "wheel_pos")).value === "-2.5", 5000, "wheel_pos -2.5 again");
});

await check("int64 beyond 2^53 exact: a decimal string to the protocol client, shown digit for digit (was ...992)", async () => {
  const c64 = JSON.parse(probe.channels.get("count64").schema).properties.value;
  assert(c64.type[0] === "string" && c64.pattern === "^-?[0-9]+$", "int64 value schema: a decimal string " + JSON.stringify(c64));
  pub("count64", "9007199254744991");
  const m = await probe.waitFor("count64", (m) => m.value === "9007199254744991", 3000, "count64 as the string 9007199254744991");
  assert(m.status === "fresh" && typeof m.value === "string", JSON.stringify(m));
  await until(async () => (await domRow(page, "count64")).value === "9007199254744991", 5000, "count64 exact in the table");
  pub("count64", "-9223372036854775808");
  await probe.waitFor("count64", (m) => m.value === "-9223372036854775808", 3000, "count64 at INT64_MIN");
  await until(async () => (await domRow(page, "count64")).value === "-9223372036854775808", 5000, "INT64_MIN in the table");
});

await check("a signal that is not written goes stale: badge and protocol message say so", async () => {
  const r = await until(async () => { const r = await domRow(page, "wheel_pos"); return r.status === "stale" && r; }, 3000, "wheel_pos stale");
  assert(r.value === "-2.5", "stale value " + r.value);
  const m = await probe.waitFor("wheel_pos", (m) => m.status === "stale" && m.value === -2.5, 3000, "-2.5 stale");
  assert(m.age_ns >= 300e6, JSON.stringify(m));
});

// The writer runs while the first browser is killed: the probe must miss nothing.
const c0 = (await stats()).changes.tick;
const seq0 = (probe.last("tick") || { seq: 0 }).seq;
// CPU seconds ccomm-web used (its /proc stat: utime + stime, in clock ticks)
const webCpu = () => {
  const f = readFileSync(`/proc/${env("WEB_PID")}/stat`, "utf8").split(") ")[1].split(" ");
  return (Number(f[11]) + Number(f[12])) / Number(env("CLK_TCK"));
};
const cpu0 = webCpu(), wall0 = Date.now();
const writer = spawn(env("PYTHON"), [env("WRITER"), NODE, String(WRITER_RATE), String(WRITER_COUNT)], { stdio: ["ignore", "pipe", "inherit"] });
let writerOut = "";
writer.stdout.on("data", (d) => { writerOut += d; });
const writerDone = new Promise((r) => writer.on("exit", (code) => r(code)));
// A plain libccomm reader of the same values: the floor the latency is compared with.
const floor = spawn(env("PYTHON"), [env("FLOOR_READER"), NODE, String(WRITER_COUNT), "60"], { stdio: ["ignore", "pipe", "inherit"] });
let floorOut = "";
floor.stdout.on("data", (d) => { floorOut += d; });
const floorDone = new Promise((r) => floor.on("exit", (code) => r(code)));

await check("arrays and events are plotted live; screenshot taken", async () => {
  await until(async () => (await domRow(page, "joint_pos")).chartPoints >= 20, 5000, "joint_pos points");
  const r = await domRow(page, "joint_pos");
  assert(r.series === 3 && r.value.startsWith("["), JSON.stringify(r));
  await until(async () => (await domRow(page, "mode_request")).chartPoints >= 2, 5000, "mode_request events plotted");
  await sleep(1500);
  await page.screenshot({ path: env("SCREENSHOT"), fullPage: true });
});

await check("a browser killed mid-stream: the server goes on, a second browser is served", async () => {
  const before = await stats();
  assert(before.clients === 2, "clients before " + JSON.stringify(before));
  assert(writer.exitCode === null, "the writer already ended: the browser would not die mid-stream");
  // playwright-core has no handle on the process any more: the browser is our only chromium child
  const pids = execFileSync("pgrep", ["-P", String(process.pid), "chromium"]).toString().trim().split("\n");
  assert(pids.length === 1 && Number(pids[0]) > 0, "chromium children: " + pids);
  process.kill(Number(pids[0]), "SIGKILL");
  await until(async () => (await stats()).clients === 1, 5000, "the killed browser's subscriptions dropped");
  browser2 = await chromium.launch(LAUNCH);
  page2 = await openPage(browser2, [], "?plot=tick,joint_pos");
  await until(() => page2.evaluate(() => document.querySelector("#conn").textContent === "connected"), 10000, "second page connected");
  const a = await until(async () => { const r = await domRow(page2, "tick"); return Number(r.value) > 0 && r; }, 5000, "tick on page 2");
  await sleep(600);
  const b = await domRow(page2, "tick");
  assert(Number(b.value) > Number(a.value) && b.plotted > a.plotted, `tick did not advance on page 2: ${a.value} -> ${b.value}`);
  const charts = await page2.evaluate(() => [...document.querySelectorAll(".chart")].map((c) => c.dataset.signal).join(","));
  assert(charts === "tick,joint_pos", "?plot=tick,joint_pos gave charts " + charts);
});

await check("bad protocol input from a client: refused, server still serves", async () => {
  const raw = new WebSocket(WS_URL, ["foxglove.sdk.v1", "foxglove.websocket.v1"]);
  await new Promise((res, rej) => { raw.on("open", res); raw.on("error", rej); });
  raw.send("{not json");
  raw.send(JSON.stringify({ op: "subscribe", subscriptions: [{ id: 1, channelId: 999999 }] }));
  raw.send(JSON.stringify({ op: "no-such-op" }));
  raw.send(Buffer.from([0x01, 0xff, 0xff]));
  await sleep(300);
  raw.terminate();
  // keepalives alone bring one message per signal and second
  const total = () => topics.reduce((sum, t) => sum + probe.received(t).length, 0);
  const n0 = total();
  await until(() => total() >= n0 + 2 * topics.length, 5000, "probe still receiving");
});

await check("bad HTTP requests: 404 outside the page's files, 400 for junk, page still served", async () => {
  const { hostname, port } = new URL(WEB_URL);
  const raw = (text) => new Promise((res, rej) => {
    const sock = net.connect(Number(port), hostname, () => sock.end(text));
    let out = "";
    sock.on("data", (d) => { out += d; });
    sock.on("end", () => res(out.split("\r\n")[0]));
    sock.on("error", rej);
  });
  const refused0 = (await stats()).http_refused;
  for (const path of ["/../../etc/passwd", "/%2e%2e/server.py", "/static/app.js", "/vendor/../cli.py", "/server.py"]) {
    const status = await raw(`GET ${path} HTTP/1.0\r\n\r\n`);
    assert(status.includes(" 404 "), path + ": " + status);
  }
  assert((await raw("JUNK\r\n\r\n")).includes(" 400 "), "junk request");
  assert((await raw("POST / HTTP/1.0\r\nContent-Length: 0\r\n\r\n")).includes(" 501 "), "POST");
  assert((await raw("GET /app.js HTTP/1.0\r\n\r\n")).includes(" 200 "), "/app.js");
  const refused = (await stats()).http_refused - refused0;
  assert(refused === 7, "refused requests counted: " + refused + " of 7");
});

await check("the protocol client lost nothing while the browser died (every new value, every event)", async () => {
  const code = await writerDone;
  assert(code === 0 && writerOut.includes("writer: done " + WRITER_COUNT), "writer exit " + code + ": " + writerOut);
  await probe.waitFor("tick", (m) => m.value === WRITER_COUNT, 3000, "the last tick");
  await sleep(300);
  const c1 = (await stats()).changes.tick;
  const ticks = probe.received("tick").map((m) => m.msg).filter((m) => m.seq > seq0);
  const seqs = [...new Set(ticks.map((m) => m.seq))];
  for (let i = 1; i < ticks.length; i++) assert(ticks[i].seq >= ticks[i - 1].seq, "seq went back at " + i);
  assert(seqs.length === c1 - c0, `probe saw ${seqs.length} new tick values, the server published ${c1 - c0}`);
  // every value written is accounted for: received, or counted in a message's gap
  const gaps = ticks.reduce((sum, m) => sum + m.gap, 0);
  assert(seqs.length + gaps === WRITER_COUNT, `${seqs.length} received + ${gaps} in gaps != ${WRITER_COUNT} written`);
  const row = await domRow(page2, "tick");
  assert(Number(row.skipped) >= 0 && row.value === String(WRITER_COUNT), "page 2 tick row " + JSON.stringify(row));
  console.log(`  # tick: ${WRITER_COUNT} written at ${WRITER_RATE} Hz, ${c1 - c0} sampled and published, all received`);
  const events = probe.received("mode_request").map((m) => m.msg.value);
  const want = Array.from({ length: WRITER_COUNT / 25 }, (_, i) => i + 1);
  assert(JSON.stringify(events) === JSON.stringify(want), "events " + JSON.stringify(events));
  assert(probe.errors.length === 0, "probe errors: " + probe.errors.join("; "));
});

await check(`a ${WRITER_RATE} Hz signal at the default --max-rate: p50 write -> protocol client within ${LAG_P50_MS} ms`, async () => {
  await writerDone;
  const webCpuShare = (webCpu() - cpu0) / ((Date.now() - wall0) / 1000);
  // Write-to-client latency of each new value (same host, same clock), for the docs.
  const firsts = new Map();
  for (const m of probe.received("tick")) if (m.msg.seq > seq0 && !firsts.has(m.msg.seq)) firsts.set(m.msg.seq, m);
  const lat = [...firsts.values()].map((m) => Number(m.mono - BigInt(m.msg.source_time_ns)) / 1e6).sort((a, b) => a - b);
  assert(lat.length > WRITER_COUNT / 2, `${lat.length} tick values received of ${WRITER_COUNT}`);
  const q = (p) => lat[Math.min(lat.length - 1, Math.floor(p * lat.length))].toFixed(2);
  console.log(`  # write -> protocol client latency (ms): min ${q(0)} p50 ${q(0.5)} p99 ${q(0.99)} max ${q(1)} (n=${lat.length})`);
  assert((await floorDone) === 0, "floor reader failed: " + floorOut);
  const f = JSON.parse(floorOut);
  console.log(`  # floor, a libccomm reader of the same values (ms): p50 ${f.p50_ms} p99 ${f.p99_ms} (n=${f.n}); ` +
              `ccomm-web p50 / floor p50 = ${(Number(q(0.5)) / f.p50_ms).toFixed(1)}`);
  console.log(`  # CPU while the writer ran: ccomm-web ${(100 * webCpuShare).toFixed(1)} % of one CPU (7 signals, 2-3 clients), ` +
              `floor reader ${(100 * f.cpu).toFixed(1)} % (1 signal); ratio ${(webCpuShare / f.cpu).toFixed(1)}`);
  assert(Number(q(0.5)) <= LAG_P50_MS, `p50 ${q(0.5)} ms > ${LAG_P50_MS} ms`);
});

await check("a page opened after the last event shows that event, not \"never\"", async () => {
  const page3 = await openPage(browser2, []);
  try {
    const last = WRITER_COUNT / 25;
    const r = await until(async () => { const r = await domRow(page3, "mode_request"); return r && r.value === String(last) && r; },
      5000, `mode_request ${last} on a page opened after the events`);
    assert(r.status !== "never" && r.seq !== "–", JSON.stringify(r));
  } finally {
    await page3.close();
  }
});

await check("y labels of 7+ digit values are not cut, and the array plot has y labels", async () => {
  pub("tick", 123456789);
  pub("joint_pos", 1234567.5, -2345678.25, 3456789);
  await until(async () => (await domRow(page2, "tick")).plotted === 123456789, 5000, "tick 123456789 plotted");
  await until(async () => (await domRow(page2, "joint_pos")).plotted === 1234567.5, 5000, "joint_pos 1234567.5 plotted");
  await sleep(300);
  for (const name of ["tick", "joint_pos"]) {
    const ax = await page2.evaluate((s) => {
      const u = window.ccommView.charts[s].plot, a = u.axes[1];
      u.ctx.font = a.font[0];
      const labels = (a._values || []).map(String);
      const widest = Math.max(0, ...labels.map((v) => u.ctx.measureText(v).width / devicePixelRatio));
      return { show: a.show !== false, labels, widest, room: a._size - a.ticks.size - a.gap };
    }, name);
    assert(ax.show && ax.labels.length >= 2, name + ": y labels " + JSON.stringify(ax));
    assert(ax.widest <= ax.room, `${name}: widest y label ${ax.widest.toFixed(1)} px > room ${ax.room} px: ${ax.labels}`);
  }
});

await check("ccommd stopped: every client is told (status message, page banner), and told when it is back", async () => {
  const pid = Number(env("CCOMMD_PID"));
  const banner = () => page2.evaluate(() => { const e = document.querySelector("#error"); return e.hidden ? "" : e.textContent; });
  let statusMsg = null;
  probe.client.on("status", (m) => { statusMsg = m; });
  process.kill(pid, "SIGSTOP");  // no heartbeat: as if it had died, without losing the segment
  try {
    const text = await until(banner, 5000, "a banner on the page");
    assert(text.includes("ccommd of node " + NODE + " is not running"), "banner: " + text);
    await until(() => statusMsg, 2000, "a status message to the protocol client");
    assert(statusMsg.level === 1 && statusMsg.id === "ccommd", JSON.stringify(statusMsg));
    assert((await stats()).daemon_alive === false, "stats.json daemon_alive");
  } finally {
    process.kill(pid, "SIGCONT");
  }
  await until(async () => (await banner()) === "", 5000, "the banner gone");
  assert((await stats()).daemon_alive === true, "stats.json daemon_alive again");
});

let restarted = null;
await check("ccomm-web restarted: the open page reconnects by itself and shows new values", async () => {
  const pid = Number(env("WEB_PID"));
  const alive = () => { try { process.kill(pid, 0); return true; } catch { return false; } };
  assert(alive(), "ccomm-web died during the tests above");
  process.kill(pid, "SIGTERM");
  await until(() => !alive(), 5000, "ccomm-web stopped by SIGTERM");
  await until(() => page2.evaluate(() => document.querySelector("#conn").textContent !== "connected"), 5000, "page sees the server gone");
  restarted = spawn(env("CCOMM"), ["--node", NODE, "web", "--port", new URL(WS_URL).port, "--http-port", new URL(WEB_URL).port],
                    { stdio: ["ignore", "inherit", "inherit"] });
  await until(() => page2.evaluate(() => document.querySelector("#conn").textContent === "connected"), 15000, "page reconnected");
  pub("wheel_pos", 42.5);
  await until(async () => (await domRow(page2, "wheel_pos")).value === "42.5", 5000, "a new value after the reconnect");
});
if (restarted) restarted.kill("SIGTERM");

probe.close();
if (browser2) await browser2.close();
if (browser && browser.isConnected()) await browser.close().catch(() => {});
console.log(`1..${n}`);
console.log(`${passed} passed, ${failed} failed`);
process.exit(failed ? 1 : 0);

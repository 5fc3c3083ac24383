// SPDX-License-Identifier: Apache-2.0
// A Foxglove WebSocket protocol client that is not ccomm's code: @foxglove/ws-protocol's
// FoxgloveClient over the `ws` package. Collects advertised channels and decoded messages.
import wsProtocol from "@foxglove/ws-protocol"; // CommonJS: no named ESM exports
import WebSocket from "ws";

const { FoxgloveClient } = wsProtocol;

export class FoxgloveProbe {
  // protocols: the subprotocols offered (default both names, as current clients do)
  constructor(url, protocols = ["foxglove.sdk.v1", "foxglove.websocket.v1"]) {
    this.url = url;
    this.protocols = protocols;
    this.channels = new Map();      // topic -> advertised channel
    this.messages = new Map();      // topic -> [{ t, msg }]
    this.subs = new Map();          // subscription id -> topic
    this.errors = [];
    this.serverInfo = null;
  }

  // Resolves once the server's channels are advertised.
  async connect(timeoutMs = 5000) {
    // foxglove.sdk.v1 is foxglove.websocket.v1 under the name foxglove-sdk servers accept;
    // FoxgloveClient leaves the choice to the socket (ws-protocol >= 0.7.5).
    const ws = new WebSocket(this.url, this.protocols);
    this.ws = ws;
    this.client = new FoxgloveClient({ ws });
    this.client.on("error", (e) => this.errors.push(String(e)));
    this.client.on("serverInfo", (info) => { this.serverInfo = info; });
    this.client.on("message", ({ subscriptionId, timestamp, data }) => {
      const topic = this.subs.get(subscriptionId);
      let msg;
      try {
        msg = JSON.parse(new TextDecoder().decode(data));
      } catch (e) {
        this.errors.push("undecodable message on " + topic + ": " + e);
        return;
      }
      // hrtime is CLOCK_MONOTONIC, the clock of the messages' source_time_ns
      this.messages.get(topic).push({ t: timestamp, mono: process.hrtime.bigint(), msg });
    });
    await new Promise((resolve, reject) => {
      const timer = setTimeout(() => reject(new Error("no advertise from " + this.url)), timeoutMs);
      this.client.on("advertise", (channels) => {
        for (const ch of channels) this.channels.set(ch.topic, ch);
        clearTimeout(timer);
        resolve();
      });
    });
  }

  subscribe(topic) {
    const ch = this.channels.get(topic);
    if (!ch) throw new Error("not advertised: " + topic);
    const id = this.client.subscribe(ch.id);
    this.subs.set(id, topic);
    this.messages.set(topic, []);
    return id;
  }

  received(topic) { return this.messages.get(topic) || []; }

  last(topic) {
    const m = this.received(topic);
    return m.length ? m[m.length - 1].msg : null;
  }

  // Waits until a message on `topic` satisfies pred(msg).
  async waitFor(topic, pred, timeoutMs, what) {
    const deadline = Date.now() + timeoutMs;
    for (;;) {
      const hit = this.received(topic).find((m) => pred(m.msg));
      if (hit) return hit.msg;
      if (Date.now() > deadline) {
        throw new Error(`${topic}: no message with ${what} within ${timeoutMs} ms (last: ${JSON.stringify(this.last(topic))})`);
      }
      await new Promise((r) => setTimeout(r, 20));
    }
  }

  close() { this.client.close(); }
}

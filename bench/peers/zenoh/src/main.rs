// SPDX-License-Identifier: Apache-2.0
//! zenoh-pingpong: the Zenoh peer of scripts/bench, board to board between two network
//! namespaces, with net_floor's and dds_pingpong's roles and protocol (bench header +
//! N payload bytes per put).
//!
//!   --role echo|ping|source|sink
//!   --listen udp/IP:PORT | --connect udp/IP:PORT   peer mode, multicast scouting off,
//!                        no TCP (only the UDP transport is compiled in)
//!   --idle-ms MS         echo/sink: give up after MS without a message (default 20000)
//! Publishers are `express` (not batched), as Zenoh's own latency examples use them.
//! The sink answers the source's probes on ccb/ack, so the source starts only once
//! the sink's subscription is known. CPU time (getrusage, every thread: Zenoh's
//! runtime too) over the measured window is printed as cpu_ns.

use ccomm_bench_common as bc;
use std::time::Duration;
use zenoh::Wait;

fn session(o: &bc::Opts) -> zenoh::Session {
    let mut c = zenoh::Config::default();
    let set = |c: &mut zenoh::Config, k: &str, v: &str| {
        c.insert_json5(k, v).unwrap_or_else(|e| bc::die(&format!("zenoh config {}: {}", k, e)))
    };
    set(&mut c, "mode", "\"peer\"");
    set(&mut c, "scouting/multicast/enabled", "false");
    set(&mut c, "listen/endpoints", &format!("[{}]", o.get("listen").map(|e| format!("\"{}\"", e)).unwrap_or_default()));
    set(&mut c, "connect/endpoints", &format!("[{}]", o.get("connect").map(|e| format!("\"{}\"", e)).unwrap_or_default()));
    zenoh::open(c).wait().unwrap_or_else(|e| bc::die(&format!("zenoh open: {}", e)))
}

struct Link {
    tx: zenoh::pubsub::Publisher<'static>,
    rx: zenoh::pubsub::Subscriber<zenoh::handlers::FifoChannelHandler<zenoh::sample::Sample>>,
}

fn link(s: &zenoh::Session, out: &'static str, inp: &'static str) -> Link {
    let tx = s.declare_publisher(out).express(true).wait().unwrap_or_else(|e| bc::die(&format!("publisher: {}", e)));
    let rx = s.declare_subscriber(inp).wait().unwrap_or_else(|e| bc::die(&format!("subscriber: {}", e)));
    Link { tx, rx }
}

impl Link {
    fn send(&self, m: &[u8]) {
        self.tx.put(m.to_vec()).wait().unwrap_or_else(|e| bc::die(&format!("put: {}", e)));
    }

    /// The next message's bytes, or None at `deadline`.
    fn recv(&self, deadline: i64) -> Option<Vec<u8>> {
        let left = deadline - bc::now_ns();
        if left <= 0 {
            return None;
        }
        match self.rx.recv_timeout(Duration::from_nanos(left as u64)) {
            Ok(Some(s)) => Some(s.payload().to_bytes().into_owned()),
            _ => None,
        }
    }
}

fn main() {
    let o = bc::Opts::parse("zenoh_rtt", &[], &["role", "listen", "connect", "idle-ms", "start-wait-ms"]);
    let role = o.get("role").unwrap_or_else(|| bc::usage_exit("--role echo|ping|source|sink")).to_string();
    let idle = o.get("idle-ms").map(|v| v.parse::<i64>().unwrap_or_else(|_| bc::usage_exit("bad --idle-ms")))
        .unwrap_or(20000) * 1_000_000;
    let start_wait = o.get("start-wait-ms").map(|v| v.parse::<i64>().unwrap_or_else(|_| bc::usage_exit("bad --start-wait-ms")))
        .unwrap_or(15000) * 1_000_000;
    let rt = bc::rt_setup(&o); // before Zenoh's runtime threads start: they inherit CPU and priority
    let s = session(&o);
    let total = (o.warmup + o.count) as usize;
    let mut m = bc::message(o.payload);
    let code = match role.as_str() {
        "echo" => {
            let l = link(&s, "ccb/pong", "ccb/ping");
            let (mut echoed, mut cpu0) = (0u64, 0i64);
            while let Some(mut b) = l.recv(bc::now_ns() + idle) {
                match bc::hdr_read(&b) {
                    Some((bc::MSG_FIN, _, _)) => break,
                    Some((bc::MSG_PING, seq, _)) => {
                        if seq != bc::PROBE_SEQ && echoed == 0 {
                            cpu0 = bc::cpu_ns();
                        }
                        b[4..8].copy_from_slice(&bc::MSG_PONG.to_le_bytes());
                        l.send(&b);
                        if seq != bc::PROBE_SEQ {
                            echoed += 1;
                        }
                    }
                    _ => {}
                }
            }
            bc::partner_line("echo", echoed, if echoed > 0 { bc::cpu_ns() - cpu0 } else { 0 });
            0
        }
        "ping" => {
            let l = link(&s, "ccb/ping", "ccb/pong");
            if !probe(&l, &mut m, bc::MSG_PING, bc::MSG_PONG, start_wait) {
                bc::die("zenoh ping: no answer from an echo");
            }
            let mut smp = vec![bc::MISSING; total];
            let period = if o.rate_hz > 0.0 { (1e9 / o.rate_hz) as i64 } else { 0 };
            let t0 = bc::now_ns() + 1_000_000;
            let mut received = 0u64;
            let cpu0 = bc::cpu_ns();
            for i in 0..total {
                if period > 0 {
                    bc::sleep_until_ns(t0 + i as i64 * period);
                }
                let ts = bc::now_ns();
                bc::hdr_write(&mut m, bc::MSG_PING, i as u64, ts);
                l.send(&m);
                while let Some(b) = l.recv(ts + o.timeout_ns) {
                    let tr = bc::now_ns();
                    if let Some((bc::MSG_PONG, seq, t)) = bc::hdr_read(&b) {
                        if (seq as usize) < total && smp[seq as usize] == bc::MISSING {
                            smp[seq as usize] = tr - t;
                            received += 1;
                            if seq as usize == i {
                                break;
                            }
                        }
                    }
                }
            }
            let cpu = bc::cpu_ns() - cpu0;
            fin(&l, &mut m, total as u64);
            bc::finish(&o, &mut smp, "zenoh_udp", if o.half { "rtt_half" } else { "rtt" }, &rt,
                       &format!(",\"program\":\"zenoh-pingpong\",\"zenoh\":\"1.10.2\",\"cpu_ns\":{},\"values\":{}",
                                cpu, 2 * received));
            if received > 0 { 0 } else { bc::EXIT_FAIL }
        }
        "source" => {
            let l = link(&s, "ccb/data", "ccb/ack");
            if !probe(&l, &mut m, bc::MSG_DATA, bc::MSG_PONG, start_wait) {
                bc::die("zenoh source: no sink answered");
            }
            let period = if o.rate_hz > 0.0 { (1e9 / o.rate_hz) as i64 } else { 0 };
            let t0 = bc::now_ns() + 1_000_000;
            let cpu0 = bc::cpu_ns();
            for i in 0..total {
                if period > 0 {
                    bc::sleep_until_ns(t0 + i as i64 * period);
                }
                bc::hdr_write(&mut m, bc::MSG_DATA, i as u64, bc::now_ns());
                l.send(&m);
            }
            let cpu = bc::cpu_ns() - cpu0;
            std::thread::sleep(Duration::from_millis(20));
            fin(&l, &mut m, total as u64);
            bc::partner_line("source", total as u64, cpu);
            0
        }
        "sink" => {
            let l = link(&s, "ccb/ack", "ccb/data");
            let mut smp = vec![bc::MISSING; total];
            let (mut received, mut first, mut last, mut cpu0) = (0u64, 0i64, 0i64, 0i64);
            while let Some(b) = l.recv(bc::now_ns() + idle) {
                let tr = bc::now_ns();
                match bc::hdr_read(&b) {
                    Some((bc::MSG_FIN, _, _)) => break,
                    Some((bc::MSG_DATA, bc::PROBE_SEQ, _)) => {
                        let mut a = b.clone();
                        a[4..8].copy_from_slice(&bc::MSG_PONG.to_le_bytes());
                        l.send(&a);
                    }
                    Some((bc::MSG_DATA, seq, t)) if (seq as usize) < total && smp[seq as usize] == bc::MISSING => {
                        if received == 0 {
                            first = tr;
                            cpu0 = bc::cpu_ns();
                        }
                        last = tr;
                        smp[seq as usize] = tr - t;
                        received += 1;
                    }
                    _ => {}
                }
            }
            let cpu = if received > 0 { bc::cpu_ns() - cpu0 } else { 0 };
            let rate = if last > first { (received - 1) as f64 * 1e9 / (last - first) as f64 } else { 0.0 };
            bc::finish(&o, &mut smp, "zenoh_udp", "one_way", &rt,
                       &format!(",\"program\":\"zenoh-pingpong\",\"zenoh\":\"1.10.2\",\"cpu_ns\":{},\"values\":{},\
                                 \"rx_values_per_s\":{:.0}", cpu, received, rate));
            if received > 0 { 0 } else { bc::EXIT_FAIL }
        }
        r => bc::usage_exit(&format!("unknown --role {}", r)),
    };
    drop(s);
    std::process::exit(code);
}

/// Send probes (seq = PROBE_SEQ) every 20 ms until one comes back as `answer`.
fn probe(l: &Link, m: &mut [u8], kind: u32, answer: u32, wait_ns: i64) -> bool {
    let give_up = bc::now_ns() + wait_ns;
    while bc::now_ns() < give_up {
        bc::hdr_write(m, kind, bc::PROBE_SEQ, bc::now_ns());
        l.send(m);
        let until = bc::now_ns() + 20_000_000;
        while let Some(b) = l.recv(until) {
            if let Some((k, bc::PROBE_SEQ, _)) = bc::hdr_read(&b) {
                if k == answer {
                    while l.recv(bc::now_ns() + 30_000_000).is_some() {} // late answers
                    return true;
                }
            }
        }
    }
    false
}

fn fin(l: &Link, m: &mut [u8], n: u64) {
    for _ in 0..3 {
        bc::hdr_write(m, bc::MSG_FIN, n, bc::now_ns());
        l.send(m);
        std::thread::sleep(Duration::from_millis(2));
    }
}

// SPDX-License-Identifier: Apache-2.0
//! iox2-pingpong: the iceoryx2 peer of scripts/bench, on one machine, measured like
//! iox_pingpong (iceoryx 2.0) and ccomm_pingpong: two processes on two CPUs, back to
//! back, RTT/2, the bench header + N payload bytes as a [u8] slice in shared memory.
//!
//!   --role echo|ping     echo answers every ping on the pong service
//!   --wait spin|event    spin: busy-poll `receive()`; event: block on a Listener that
//!                        the other side's Notifier wakes after each send
//!   --service NAME       service name prefix (unique per run)
//! Common options: see bench/bench_common.h. CPU time (getrusage, every thread) over
//! the measured window is printed as cpu_ns (the echo on stderr).

use ccomm_bench_common as bc;
use iceoryx2::prelude::*;
use std::time::Duration;

type Pub = iceoryx2::port::publisher::Publisher<ipc::Service, [u8], ()>;
type Sub = iceoryx2::port::subscriber::Subscriber<ipc::Service, [u8], ()>;

struct Ports {
    tx: Pub,
    rx: Sub,
    notifier: Option<iceoryx2::port::notifier::Notifier<ipc::Service>>,
    listener: Option<iceoryx2::port::listener::Listener<ipc::Service>>,
}

fn open(node: &Node<ipc::Service>, base: &str, out: &str, inp: &str, event: bool, max_len: usize) -> Ports {
    let name = |s: &str| -> ServiceName {
        format!("{}/{}", base, s).as_str().try_into().unwrap_or_else(|_| bc::die("bad --service"))
    };
    let svc = |s: &str| {
        node.service_builder(&name(s))
            .publish_subscribe::<[u8]>()
            .subscriber_max_buffer_size(4)
            .history_size(0)
            .open_or_create()
            .unwrap_or_else(|e| bc::die(&format!("iceoryx2 service {}: {:?}", s, e)))
    };
    let (so, si) = (svc(out), svc(inp));
    let tx = so.publisher_builder().initial_max_slice_len(max_len).create()
        .unwrap_or_else(|e| bc::die(&format!("iceoryx2 publisher: {:?}", e)));
    let rx = si.subscriber_builder().create().unwrap_or_else(|e| bc::die(&format!("iceoryx2 subscriber: {:?}", e)));
    let (mut notifier, mut listener) = (None, None);
    if event {
        let ev = |s: &str| {
            node.service_builder(&name(&format!("{}-ev", s))).event().open_or_create()
                .unwrap_or_else(|e| bc::die(&format!("iceoryx2 event {}: {:?}", s, e)))
        };
        notifier = Some(ev(out).notifier_builder().create().unwrap_or_else(|e| bc::die(&format!("notifier: {:?}", e))));
        listener = Some(ev(inp).listener_builder().create().unwrap_or_else(|e| bc::die(&format!("listener: {:?}", e))));
    }
    Ports { tx, rx, notifier, listener }
}

impl Ports {
    fn send(&self, msg: &[u8]) {
        let s = self.tx.loan_slice_uninit(msg.len()).unwrap_or_else(|e| bc::die(&format!("loan: {:?}", e)));
        s.write_from_slice(msg).send().unwrap_or_else(|e| bc::die(&format!("send: {:?}", e)));
        if let Some(n) = &self.notifier {
            let _ = n.notify();
        }
    }

    /// The next message (copied into `buf`, its length returned) or None at `deadline`.
    /// `lazy`: poll every 50 µs instead of spinning (a SCHED_FIFO spinner waiting seconds
    /// for its partner to start would take the CPU from everything else).
    fn recv(&self, buf: &mut [u8], deadline: i64, lazy: bool) -> Option<usize> {
        loop {
            match self.rx.receive() {
                Ok(Some(s)) => {
                    let n = s.payload().len().min(buf.len());
                    buf[..n].copy_from_slice(&s.payload()[..n]);
                    return Some(n);
                }
                Ok(None) => {}
                Err(e) => bc::die(&format!("receive: {:?}", e)),
            }
            let left = deadline - bc::now_ns();
            if left <= 0 {
                return None;
            }
            match &self.listener {
                Some(l) => {
                    let _ = l.timed_wait(|_| {}, Duration::from_nanos(left.min(100_000_000) as u64));
                }
                None if lazy => std::thread::sleep(Duration::from_micros(50)),
                None => std::hint::spin_loop(),
            }
        }
    }
}

fn main() {
    let o = bc::Opts::parse("iox2_rtt", &[], &["role", "wait", "service"]);
    let role = o.get("role").unwrap_or_else(|| bc::usage_exit("--role echo|ping"));
    let event = match o.get("wait").unwrap_or("spin") {
        "spin" => false,
        "event" => true,
        w => bc::usage_exit(&format!("unknown --wait {}", w)),
    };
    let base = o.get("service").unwrap_or("ccb");
    set_log_level(LogLevel::Error); // not the note that no config file exists: the defaults are meant
    let rt = bc::rt_setup(&o);
    let node = NodeBuilder::new().signal_handling_mode(SignalHandlingMode::Disabled).create::<ipc::Service>()
        .unwrap_or_else(|e| bc::die(&format!("iceoryx2 node: {:?}", e)));
    let max_len = bc::HDR_SIZE + o.payload; // the echo is given the same --payload
    let mut buf = vec![0u8; max_len];
    if role == "echo" {
        let p = open(&node, base, "pong", "ping", event, max_len);
        let (mut echoed, mut cpu0) = (0u64, 0i64);
        while let Some(n) = p.recv(&mut buf, bc::now_ns() + 30_000_000_000, echoed == 0) {
            match bc::hdr_read(&buf[..n]) {
                Some((bc::MSG_FIN, _, _)) => break,
                Some((bc::MSG_PING, seq, _)) => {
                    if seq != bc::PROBE_SEQ && echoed == 0 {
                        cpu0 = bc::cpu_ns();
                    }
                    buf[4..8].copy_from_slice(&bc::MSG_PONG.to_le_bytes());
                    p.send(&buf[..n]);
                    if seq != bc::PROBE_SEQ {
                        echoed += 1;
                    }
                }
                _ => {}
            }
        }
        bc::partner_line("echo", echoed, if echoed > 0 { bc::cpu_ns() - cpu0 } else { 0 });
        return;
    }
    if role != "ping" {
        bc::usage_exit("--role echo|ping");
    }
    let p = open(&node, base, "ping", "pong", event, max_len);
    let mut m = bc::message(o.payload);
    // Probe until the echo answers: both directions are connected then.
    let give_up = bc::now_ns() + 15_000_000_000;
    let mut answered = false;
    while !answered && bc::now_ns() < give_up {
        bc::hdr_write(&mut m, bc::MSG_PING, bc::PROBE_SEQ, bc::now_ns());
        p.send(&m);
        let until = bc::now_ns() + 20_000_000;
        while let Some(n) = p.recv(&mut buf, until, true) {
            if let Some((bc::MSG_PONG, bc::PROBE_SEQ, _)) = bc::hdr_read(&buf[..n]) {
                answered = true;
                break;
            }
        }
    }
    if !answered {
        bc::die("iox2 ping: no answer from an echo within 15 s");
    }
    while p.recv(&mut buf, bc::now_ns() + 30_000_000, true).is_some() {} // late probe answers
    let total = (o.warmup + o.count) as usize;
    let mut s = vec![bc::MISSING; total];
    let period = if o.rate_hz > 0.0 { (1e9 / o.rate_hz) as i64 } else { 0 };
    let t0 = bc::now_ns() + 1_000_000;
    let (mut received, mut foreign) = (0u64, 0u64);
    let cpu0 = bc::cpu_ns();
    for i in 0..total {
        if period > 0 {
            bc::sleep_until_ns(t0 + i as i64 * period);
        }
        let ts = bc::now_ns();
        bc::hdr_write(&mut m, bc::MSG_PING, i as u64, ts);
        p.send(&m);
        while let Some(n) = p.recv(&mut buf, ts + o.timeout_ns, false) {
            let tr = bc::now_ns();
            match bc::hdr_read(&buf[..n]) {
                Some((bc::MSG_PONG, seq, t)) if (seq as usize) < total && s[seq as usize] == bc::MISSING => {
                    s[seq as usize] = tr - t;
                    received += 1;
                    if seq as usize == i {
                        break;
                    }
                }
                _ => foreign += 1,
            }
        }
    }
    let cpu = bc::cpu_ns() - cpu0;
    bc::hdr_write(&mut m, bc::MSG_FIN, total as u64, bc::now_ns());
    p.send(&m);
    let extra = format!(",\"program\":\"iox2-pingpong\",\"wait\":\"{}\",\"iceoryx2\":\"0.10.0\",\"foreign\":{},\
                         \"cpu_ns\":{},\"values\":{}", if event { "event" } else { "spin" }, foreign, cpu, 2 * received);
    bc::finish(&o, &mut s, "iceoryx2", if o.half { "rtt_half" } else { "rtt" }, &rt, &extra);
    std::process::exit(if received > 0 { 0 } else { bc::EXIT_FAIL });
}

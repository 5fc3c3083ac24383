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
use ccomm_bench_common::Link as _;
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

impl bc::Link for Ports {
    fn send(&self, msg: &[u8]) {
        let s = self.tx.loan_slice_uninit(msg.len()).unwrap_or_else(|e| bc::die(&format!("loan: {:?}", e)));
        s.write_from_slice(msg).send().unwrap_or_else(|e| bc::die(&format!("send: {:?}", e)));
        if let Some(n) = &self.notifier {
            let _ = n.notify();
        }
    }

    /// The next message copied into `buf`. `patient`: poll every 50 µs instead of spinning
    /// (a SCHED_FIFO spinner waiting seconds for its partner to start would take the CPU
    /// from everything else).
    fn recv(&mut self, buf: &mut Vec<u8>, deadline: i64, patient: bool) -> bool {
        loop {
            match self.rx.receive() {
                Ok(Some(s)) => {
                    buf.clear();
                    buf.extend_from_slice(s.payload());
                    return true;
                }
                Ok(None) => {}
                Err(e) => bc::die(&format!("receive: {:?}", e)),
            }
            let left = deadline - bc::now_ns();
            if left <= 0 {
                return false;
            }
            match &self.listener {
                Some(l) => {
                    let _ = l.timed_wait(|_| {}, Duration::from_nanos(left.min(100_000_000) as u64));
                }
                None if patient => std::thread::sleep(Duration::from_micros(50)),
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
    if role == "echo" {
        let mut p = open(&node, base, "pong", "ping", event, max_len);
        bc::echo(&mut p, 30_000_000_000, max_len);
        return;
    }
    if role != "ping" {
        bc::usage_exit("--role echo|ping");
    }
    let mut p = open(&node, base, "ping", "pong", event, max_len);
    let mut m = bc::message(o.payload);
    if !bc::probe(&mut p, &mut m, bc::MSG_PING, bc::MSG_PONG, 15_000_000_000) {
        bc::die("iox2 ping: no answer from an echo within 15 s");
    }
    let mut r = bc::ping(&mut p, &o, &mut m);
    bc::hdr_write(&mut m, bc::MSG_FIN, o.warmup + o.count, bc::now_ns());
    p.send(&m);
    let extra = format!(",\"program\":\"iox2-pingpong\",\"wait\":\"{}\",\"iceoryx2\":\"0.10.0\",\"foreign\":{},\
                         \"cpu_ns\":{},\"values\":{}", if event { "event" } else { "spin" }, r.foreign, r.cpu_ns,
                        2 * r.received);
    bc::finish(&o, &mut r.samples, "iceoryx2", if o.half { "rtt_half" } else { "rtt" }, &rt, &extra);
    std::process::exit(if r.received > 0 { 0 } else { bc::EXIT_FAIL });
}

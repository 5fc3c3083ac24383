// SPDX-License-Identifier: Apache-2.0
//! The Rust side of bench/bench_common.h, for the peer programs in bench/peers: the same
//! command line (--name --payload --rate --count --warmup --timeout-ms --half --cpu
//! --prio --no-mlock --dump), the same 24-byte message header, nearest-rank statistics
//! and the same one-line JSON result, so scripts/bench treats them like the C programs;
//! and the echo, probe and ping loops, written once over the `Link` each peer implements
//! for its middleware.
//! libc is declared here by hand (a few calls) to keep the peers free of extra crates.

use std::io::Write;

pub const EXIT_FAIL: i32 = 1;
pub const EXIT_USAGE: i32 = 2;
pub const HDR_SIZE: usize = 24;
pub const MAGIC: u32 = 0x4343_4231; // "CCB1"
pub const MSG_PING: u32 = 1;
pub const MSG_PONG: u32 = 2;
pub const MSG_DATA: u32 = 3;
pub const MSG_FIN: u32 = 4;
pub const PROBE_SEQ: u64 = u64::MAX;
pub const MISSING: i64 = i64::MIN;

/// Options shared by every bench program, and the program's own ones (`extra`: name -> value).
pub struct Opts {
    pub name: String,
    pub dump: Option<String>,
    pub cpu: Option<usize>,
    pub prio: i32,
    pub payload: usize,
    pub rate_hz: f64,
    pub count: u64,
    pub warmup: u64,
    pub timeout_ns: i64,
    pub half: bool,
    pub no_mlock: bool,
    pub extra: Vec<(String, String)>,
}

impl Opts {
    /// Parse argv; `flags` are the program's value-less options, `valued` those with a value.
    pub fn parse(name: &str, flags: &[&str], valued: &[&str]) -> Opts {
        let mut o = Opts { name: name.to_string(), dump: None, cpu: None, prio: 0, payload: 8, rate_hz: 0.0,
                           count: 10000, warmup: 100, timeout_ns: 1_000_000_000, half: false, no_mlock: false,
                           extra: Vec::new() };
        let args: Vec<String> = std::env::args().skip(1).collect();
        let mut i = 0;
        while i < args.len() {
            let a = args[i].trim_start_matches("--").to_string();
            let flag = matches!(a.as_str(), "half" | "no-mlock") || flags.contains(&a.as_str());
            let val = if flag { String::new() } else {
                i += 1;
                match args.get(i) { Some(v) => v.clone(), None => usage_exit(&format!("--{} needs a value", a)) }
            };
            let bad = || -> ! { usage_exit(&format!("bad value for --{}: {}", a, val)) };
            match a.as_str() {
                "name" => o.name = val,
                "dump" => o.dump = Some(val),
                "cpu" => o.cpu = Some(val.split(',').next().unwrap_or("").parse().unwrap_or_else(|_| bad())),
                "prio" => o.prio = val.parse().ok().filter(|p| (0..=99).contains(p)).unwrap_or_else(|| bad()),
                "payload" => o.payload = val.parse().ok().filter(|p| *p <= 65000).unwrap_or_else(|| bad()),
                "rate" => o.rate_hz = val.parse().ok().filter(|r: &f64| *r >= 0.0).unwrap_or_else(|| bad()),
                "count" => o.count = val.parse().ok().filter(|c| *c > 0).unwrap_or_else(|| bad()),
                "warmup" => o.warmup = val.parse().unwrap_or_else(|_| bad()),
                "timeout-ms" => o.timeout_ns = val.parse::<i64>().ok().filter(|t| *t > 0).unwrap_or_else(|| bad())
                    * 1_000_000,
                "half" => o.half = true,
                "no-mlock" => o.no_mlock = true,
                _ if flag || valued.contains(&a.as_str()) => o.extra.push((a, val)),
                _ => usage_exit(&format!("unknown option --{}", a)),
            }
            i += 1;
        }
        o
    }

    pub fn get(&self, key: &str) -> Option<&str> {
        self.extra.iter().rev().find(|(k, _)| k == key).map(|(_, v)| v.as_str())
    }

    pub fn has(&self, key: &str) -> bool {
        self.get(key).is_some()
    }
}

pub fn usage_exit(msg: &str) -> ! {
    eprintln!("{}", msg);
    std::process::exit(EXIT_USAGE)
}

pub fn die(msg: &str) -> ! {
    eprintln!("{}", msg);
    std::process::exit(EXIT_FAIL)
}

// ---- clock and CPU time ----

#[repr(C)]
struct Timespec {
    tv_sec: i64,
    tv_nsec: i64,
}
#[repr(C)]
struct Timeval {
    tv_sec: i64,
    tv_usec: i64,
}
#[repr(C)]
struct Rusage {
    utime: Timeval,
    stime: Timeval,
    rest: [i64; 14],
}
#[repr(C)]
struct SchedParam {
    prio: i32,
}
extern "C" {
    fn clock_gettime(clk: i32, ts: *mut Timespec) -> i32;
    fn getrusage(who: i32, ru: *mut Rusage) -> i32;
    fn sched_setaffinity(pid: i32, size: usize, mask: *const u64) -> i32;
    fn sched_setscheduler(pid: i32, policy: i32, p: *const SchedParam) -> i32;
    fn mlockall(flags: i32) -> i32;
}
const CLOCK_MONOTONIC: i32 = 1;

/// CLOCK_MONOTONIC in ns: the clock of the C programs, shared by two namespaces.
pub fn now_ns() -> i64 {
    let mut ts = Timespec { tv_sec: 0, tv_nsec: 0 };
    unsafe { clock_gettime(CLOCK_MONOTONIC, &mut ts) };
    ts.tv_sec * 1_000_000_000 + ts.tv_nsec
}

/// utime + stime of this process (every thread) in ns.
pub fn cpu_ns() -> i64 {
    let mut ru = Rusage { utime: Timeval { tv_sec: 0, tv_usec: 0 }, stime: Timeval { tv_sec: 0, tv_usec: 0 },
                          rest: [0; 14] };
    unsafe { getrusage(0, &mut ru) }; // RUSAGE_SELF
    (ru.utime.tv_sec + ru.stime.tv_sec) * 1_000_000_000 + (ru.utime.tv_usec + ru.stime.tv_usec) * 1000
}

pub fn sleep_until_ns(t: i64) {
    let d = t - now_ns();
    if d > 0 {
        std::thread::sleep(std::time::Duration::from_nanos(d as u64));
    }
}

/// What the real-time set-up obtained (for the result line).
pub struct Rt {
    pub cpu: i64,
    pub prio: i32,
    pub mlocked: bool,
}

/// Pin, SCHED_FIFO and mlockall where permitted; call before the middleware starts its
/// threads so they inherit CPU and priority. Failures are warnings, as in C.
pub fn rt_setup(o: &Opts) -> Rt {
    let mut rt = Rt { cpu: -1, prio: 0, mlocked: false };
    if let Some(c) = o.cpu {
        let mut mask = [0u64; 16];
        if c < 1024 {
            mask[c / 64] |= 1 << (c % 64);
            if unsafe { sched_setaffinity(0, std::mem::size_of_val(&mask), mask.as_ptr()) } == 0 {
                rt.cpu = c as i64;
            } else {
                eprintln!("warning: cannot pin to CPU {}", c);
            }
        }
    }
    if o.prio > 0 {
        if unsafe { sched_setscheduler(0, 1, &SchedParam { prio: o.prio }) } == 0 {
            rt.prio = o.prio;
        } else {
            eprintln!("warning: SCHED_FIFO {} refused", o.prio);
        }
    }
    if !o.no_mlock {
        rt.mlocked = unsafe { mlockall(3) } == 0; // MCL_CURRENT | MCL_FUTURE
    }
    rt
}

// ---- the message header ----

pub fn hdr_write(p: &mut [u8], kind: u32, seq: u64, t_ns: i64) {
    p[0..4].copy_from_slice(&MAGIC.to_le_bytes());
    p[4..8].copy_from_slice(&kind.to_le_bytes());
    p[8..16].copy_from_slice(&seq.to_le_bytes());
    p[16..24].copy_from_slice(&(t_ns as u64).to_le_bytes());
}

/// (type, seq, send time) or None if this is not a bench message.
pub fn hdr_read(p: &[u8]) -> Option<(u32, u64, i64)> {
    if p.len() < HDR_SIZE || u32::from_le_bytes(p[0..4].try_into().ok()?) != MAGIC {
        return None;
    }
    Some((u32::from_le_bytes(p[4..8].try_into().ok()?), u64::from_le_bytes(p[8..16].try_into().ok()?),
          u64::from_le_bytes(p[16..24].try_into().ok()?) as i64))
}

/// A message of the given payload: header space, then the payload bytes as in C.
pub fn message(payload: usize) -> Vec<u8> {
    (0..HDR_SIZE + payload).map(|i| if i < HDR_SIZE { 0 } else { i as u8 }).collect()
}

// ---- the echo and ping sides, over any middleware ----

/// What the echo, probe and ping loops need from a middleware: one publisher, one
/// subscriber.
pub trait Link {
    fn send(&self, msg: &[u8]);
    /// The next message into `buf` (replacing its contents); false at `deadline`.
    /// `patient`: a long wait is expected (the partner may not have started), so the
    /// link may poll slowly rather than spin.
    fn recv(&mut self, buf: &mut Vec<u8>, deadline: i64, patient: bool) -> bool;
}

/// Send probes (seq = PROBE_SEQ, type `kind`) every 20 ms until one comes back as
/// `answer` or `wait_ns` has passed; then drop late answers for 30 ms. True if answered:
/// both directions are connected then.
pub fn probe<L: Link>(l: &mut L, m: &mut [u8], kind: u32, answer: u32, wait_ns: i64) -> bool {
    let give_up = now_ns() + wait_ns;
    let mut b = Vec::with_capacity(m.len());
    while now_ns() < give_up {
        hdr_write(m, kind, PROBE_SEQ, now_ns());
        l.send(m);
        let until = now_ns() + 20_000_000;
        while l.recv(&mut b, until, true) {
            if matches!(hdr_read(&b), Some((k, PROBE_SEQ, _)) if k == answer) {
                while l.recv(&mut b, now_ns() + 30_000_000, true) {}
                return true;
            }
        }
    }
    false
}

/// The echo: answers every ping with a pong of the same bytes until a FIN or `idle_ns`
/// without a message; prints its partner line (pings echoed, CPU time from the first
/// measured ping on).
pub fn echo<L: Link>(l: &mut L, idle_ns: i64, max_len: usize) {
    let (mut echoed, mut cpu0) = (0u64, 0i64);
    let mut b = Vec::with_capacity(max_len);
    while l.recv(&mut b, now_ns() + idle_ns, echoed == 0) {
        match hdr_read(&b) {
            Some((MSG_FIN, _, _)) => break,
            Some((MSG_PING, seq, _)) => {
                if seq != PROBE_SEQ && echoed == 0 {
                    cpu0 = cpu_ns();
                }
                b[4..8].copy_from_slice(&MSG_PONG.to_le_bytes());
                l.send(&b);
                if seq != PROBE_SEQ {
                    echoed += 1;
                }
            }
            _ => {}
        }
    }
    partner_line("echo", echoed, if echoed > 0 { cpu_ns() - cpu0 } else { 0 });
}

/// What the measured pings gave: round trips by sequence number (MISSING = no pong
/// within --timeout-ms), pongs received, other messages, CPU time of the loop.
pub struct PingRun {
    pub samples: Vec<i64>,
    pub received: u64,
    pub foreign: u64,
    pub cpu_ns: i64,
}

/// --warmup + --count pings in `m` at --rate (absolute sleeps; 0 = back to back), each
/// waiting up to --timeout-ms for its pong (earlier pongs that come late still count).
pub fn ping<L: Link>(l: &mut L, o: &Opts, m: &mut [u8]) -> PingRun {
    let total = (o.warmup + o.count) as usize;
    let mut r = PingRun { samples: vec![MISSING; total], received: 0, foreign: 0, cpu_ns: 0 };
    let mut b = Vec::with_capacity(m.len());
    let period = if o.rate_hz > 0.0 { (1e9 / o.rate_hz) as i64 } else { 0 };
    let t0 = now_ns() + 1_000_000;
    let cpu0 = cpu_ns();
    for i in 0..total {
        if period > 0 {
            sleep_until_ns(t0 + i as i64 * period);
        }
        let ts = now_ns();
        hdr_write(m, MSG_PING, i as u64, ts);
        l.send(m);
        while l.recv(&mut b, ts + o.timeout_ns, false) {
            let tr = now_ns();
            match hdr_read(&b) {
                Some((MSG_PONG, seq, t)) if (seq as usize) < total && r.samples[seq as usize] == MISSING => {
                    r.samples[seq as usize] = tr - t;
                    r.received += 1;
                    if seq as usize == i {
                        break;
                    }
                }
                _ => r.foreign += 1,
            }
        }
    }
    r.cpu_ns = cpu_ns() - cpu0;
    r
}

// ---- samples and the result line ----

/// Nearest-rank percentile of a sorted slice (bench_pct).
fn pct(s: &[i64], q: f64) -> i64 {
    if s.is_empty() {
        return 0;
    }
    let r = q * s.len() as f64;
    let mut k = r as usize;
    if (k as f64) < r {
        k += 1;
    }
    s[k.clamp(1, s.len()) - 1]
}

/// Halve (--half), dump (--dump) and print the JSON line of samples[warmup..];
/// `extra` is a JSON fragment starting with a comma.
pub fn finish(o: &Opts, samples: &mut [i64], transport: &str, metric: &str, rt: &Rt, extra: &str) {
    if o.half {
        for v in samples.iter_mut().filter(|v| **v != MISSING) {
            *v /= 2;
        }
    }
    let from = (o.warmup as usize).min(samples.len());
    let measured = &samples[from..];
    if let Some(path) = &o.dump {
        let mut f = std::io::BufWriter::new(std::fs::File::create(path).unwrap_or_else(|e| die(&format!(
            "cannot write {}: {}", path, e))));
        for (i, v) in measured.iter().enumerate() {
            let _ = writeln!(f, "{}\t{}", from + i, if *v == MISSING { -1 } else { *v });
        }
    }
    let mut got: Vec<i64> = measured.iter().copied().filter(|v| *v != MISSING).collect();
    got.sort_unstable();
    let lost = measured.len() - got.len();
    let mean = if got.is_empty() { 0.0 } else { got.iter().map(|v| *v as f64).sum::<f64>() / got.len() as f64 };
    println!("{{\"name\":\"{}\",\"transport\":\"{}\",\"payload_bytes\":{},\"rate_hz\":{},\"min_ns\":{},\
              \"p50_ns\":{},\"p90_ns\":{},\"p99_ns\":{},\"p999_ns\":{},\"max_ns\":{},\"mean_ns\":{:.1},\
              \"count\":{},\"lost\":{},\"metric\":\"{}\",\"warmup\":{},\"cpu\":{},\"prio\":{},\"mlocked\":{}{}}}",
             o.name, transport, o.payload, o.rate_hz, got.first().copied().unwrap_or(0), pct(&got, 0.5),
             pct(&got, 0.9), pct(&got, 0.99), pct(&got, 0.999), got.last().copied().unwrap_or(0), mean, got.len(),
             lost, metric, o.warmup, rt.cpu, rt.prio, rt.mlocked, extra);
    let _ = std::io::stdout().flush();
}

/// The partner's (echo, source) closing line on stderr: what it did and its CPU time.
pub fn partner_line(role: &str, count: u64, cpu_ns: i64) {
    eprintln!("{{\"role\":\"{}\",\"count\":{},\"cpu_ns\":{}}}", role, count, cpu_ns);
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::cell::RefCell;
    use std::collections::VecDeque;

    /// An echo inside the link: every message sent comes back as a pong, except those
    /// whose sequence number is in `drop`; `foreign` messages come before the first pong.
    struct Loopback {
        queue: RefCell<VecDeque<Vec<u8>>>,
        drop: Vec<u64>,
        foreign: usize,
        sent: RefCell<u64>,
    }

    fn loopback(drop: Vec<u64>, foreign: usize) -> Loopback {
        Loopback { queue: RefCell::new(VecDeque::new()), drop, foreign, sent: RefCell::new(0) }
    }

    impl Link for Loopback {
        fn send(&self, msg: &[u8]) {
            *self.sent.borrow_mut() += 1;
            if !self.drop.contains(&hdr_read(msg).unwrap().1) {
                let mut pong = msg.to_vec();
                pong[4..8].copy_from_slice(&MSG_PONG.to_le_bytes());
                self.queue.borrow_mut().push_back(pong);
            }
        }
        fn recv(&mut self, buf: &mut Vec<u8>, deadline: i64, _patient: bool) -> bool {
            if self.foreign > 0 {
                self.foreign -= 1;
                *buf = vec![0u8; HDR_SIZE];
                return true;
            }
            match self.queue.borrow_mut().pop_front() {
                Some(m) => {
                    *buf = m;
                    true
                }
                None => {
                    sleep_until_ns(deadline);
                    false
                }
            }
        }
    }

    fn opts(count: u64, warmup: u64) -> Opts {
        Opts { name: "t".into(), dump: None, cpu: None, prio: 0, payload: 8, rate_hz: 0.0, count, warmup,
               timeout_ns: 1_000_000, half: false, no_mlock: true, extra: Vec::new() }
    }

    #[test]
    fn ping_records_each_round_trip_and_counts_the_lost_and_the_foreign() {
        let mut l = loopback(vec![3, 7], 1);
        let o = opts(8, 2);
        let mut m = message(o.payload);
        let r = ping(&mut l, &o, &mut m);
        assert_eq!(*l.sent.borrow(), 10);
        assert_eq!((r.received, r.foreign), (8, 1));
        let lost: Vec<usize> = (0..10).filter(|i| r.samples[*i] == MISSING).collect();
        assert_eq!(lost, vec![3, 7]);
        assert!(r.samples.iter().filter(|v| **v != MISSING).all(|v| *v >= 0));
    }

    #[test]
    fn echo_answers_pings_until_the_fin() {
        let mut l = loopback(vec![], 0);
        let mut m = message(8);
        for (kind, seq) in [(MSG_PING, PROBE_SEQ), (MSG_PING, 0), (MSG_DATA, 1), (MSG_PING, 2), (MSG_FIN, 3)] {
            hdr_write(&mut m, kind, seq, now_ns());
            l.queue.borrow_mut().push_back(m.clone());
        }
        echo(&mut l, 1_000_000_000, m.len());
        assert_eq!(*l.sent.borrow(), 3); // the probe and the two pings, not the data message
        let answers: Vec<_> = l.queue.borrow().iter().map(|b| hdr_read(b).unwrap()).collect();
        assert_eq!(answers.iter().map(|a| (a.0, a.1)).collect::<Vec<_>>(),
                   vec![(MSG_PONG, PROBE_SEQ), (MSG_PONG, 0), (MSG_PONG, 2)]);
    }

    #[test]
    fn probe_is_answered_and_late_answers_are_dropped() {
        let mut l = loopback(vec![], 0);
        let mut m = message(8);
        assert!(probe(&mut l, &mut m, MSG_PING, MSG_PONG, 1_000_000_000));
        assert!(l.queue.borrow().is_empty());
        let mut silent = loopback(vec![PROBE_SEQ], 0);
        assert!(!probe(&mut silent, &mut m, MSG_PING, MSG_PONG, 50_000_000));
    }
}

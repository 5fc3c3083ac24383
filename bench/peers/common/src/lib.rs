// SPDX-License-Identifier: Apache-2.0
//! The Rust side of bench/bench_common.h, for the peer programs in bench/peers: the same
//! command line (--name --payload --rate --count --warmup --timeout-ms --half --cpu
//! --prio --no-mlock --dump), the same 24-byte message header, nearest-rank statistics
//! and the same one-line JSON result, so scripts/bench treats them like the C programs.
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

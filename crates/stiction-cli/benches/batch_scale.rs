//! How `stiction batch` scales: N simulated loops of S samples written as one long-format CSV
//! (streamed to disk, one loop in memory at a time), then the `stiction` binary run on it, with
//! and without the closed-loop estimate. Reports wall time, loops per second and the peak
//! resident memory of the batch process.
//!
//!     cargo bench -p stiction-cli --bench batch_scale -- [N ...] [--samples S] [--threads T] [--dir DIR] [--no-quantify-only] [--keep]
//!
//! N defaults to 1000; e.g. `-- 1000 10000`. S, the samples per loop, defaults to 2000; the
//! memory figure of a day of 1 s samples per loop (about 3.5 GB of CSV for 1000 loops) is
//! `-- 1000 --samples 86400 --threads 2`. The mix: a quarter each of sticky valves (Stenman d
//! uniform in 1..4 % with normal PI tuning), healthy valves with aggressive tuning (near the
//! stability limit), healthy valves with a sinusoidal disturbance on the PV (period 100 to 250 s),
//! and healthy valves with noise only; three FOPTD processes, PV noise 0.02, 0.1 or 0.3, all chosen
//! by a seeded hash of the loop number, so a given N always gives the same file.

use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};
use stiction_core::models::{Model, Stenman};
use stiction_core::sim::{ClosedLoop, Pi, Process, Signal};

/// SplitMix64: a well-mixed number from a loop number and a stream.
fn mix(i: u64, stream: u64) -> u64 {
    let mut z = i
        .wrapping_mul(0x9E37_79B9_7F4A_7C15)
        .wrapping_add(stream.wrapping_mul(0xBF58_476D_1CE4_E5B9));
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

fn unit(i: u64, stream: u64) -> f64 {
    (mix(i, stream) >> 11) as f64 / (1u64 << 53) as f64
}

const FAMILIES: [&str; 4] = ["sticky", "aggressive", "disturbance", "noise"];

/// Loop `i` of the mix.
fn loop_setup(i: u64, samples: usize) -> (&'static str, ClosedLoop) {
    // process, normal tuning, aggressive tuning (as in stiction-core's diagnose benchmark)
    let processes = [
        (
            Process::Foptd {
                k: 3.0,
                tau: 10.0,
                delay: 10.0,
            },
            Pi { kc: 0.2, ti: 10.0 },
            Pi { kc: 0.4, ti: 12.0 },
        ),
        (
            Process::Foptd {
                k: 1.0,
                tau: 30.0,
                delay: 5.0,
            },
            Pi { kc: 1.0, ti: 30.0 },
            Pi { kc: 6.0, ti: 12.0 },
        ),
        (
            Process::Foptd {
                k: 2.0,
                tau: 5.0,
                delay: 2.0,
            },
            Pi { kc: 0.4, ti: 5.0 },
            Pi { kc: 1.2, ti: 4.0 },
        ),
    ];
    let family = FAMILIES[(i % 4) as usize];
    let (process, normal, aggressive) = processes[(mix(i, 1) % 3) as usize];
    let d = if family == "sticky" {
        1.0 + 3.0 * unit(i, 2)
    } else {
        0.0
    };
    let mut cl = ClosedLoop::new(Model::Stenman(Stenman { d }));
    cl.process = process;
    cl.pi = if family == "aggressive" {
        aggressive
    } else {
        normal
    };
    cl.samples = samples;
    cl.noise = [0.02, 0.1, 0.3][(mix(i, 3) % 3) as usize];
    cl.seed = mix(i, 4);
    if family == "disturbance" {
        cl.disturbance = Some(Signal::Sine {
            amplitude: 1.0,
            period: 100.0 + 150.0 * unit(i, 5),
            offset: 0.0,
        });
    }
    (family, cl)
}

/// Write N loops as `loop_id,t,sp,op,pv`, one loop in memory at a time.
fn generate(path: &Path, n: u64, samples: usize) -> std::io::Result<(u64, f64)> {
    let t0 = Instant::now();
    let mut w = BufWriter::with_capacity(1 << 20, std::fs::File::create(path)?);
    writeln!(w, "loop_id,t,sp,op,pv")?;
    for i in 0..n {
        let (family, cl) = loop_setup(i, samples);
        let data = cl.run().expect("a valid simulated loop");
        for k in 0..data.t.len() {
            writeln!(
                w,
                "L{i:06}_{family},{},{},{:.4},{:.4}",
                data.t[k], data.sp[k], data.op[k], data.pv[k]
            )?;
        }
    }
    w.flush()?;
    Ok((std::fs::metadata(path)?.len(), t0.elapsed().as_secs_f64()))
}

/// A field of `/usr/bin/time -v`'s report, e.g. "Maximum resident set size (kbytes)".
fn time_field(report: &str, name: &str) -> Option<f64> {
    report
        .lines()
        .find(|l| l.trim_start().starts_with(name))
        .and_then(|l| l.rsplit(':').next())
        .and_then(|v| v.trim().parse().ok())
}

/// VmHWM of a running process, kB.
fn vm_hwm_kb(pid: u32) -> Option<u64> {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    status
        .lines()
        .find(|l| l.starts_with("VmHWM:"))?
        .split_whitespace()
        .nth(1)?
        .parse()
        .ok()
}

struct Run {
    seconds: f64,
    /// User + system CPU time (with /usr/bin/time), seconds.
    cpu: Option<f64>,
    peak_kb: Option<u64>,
    counts: String,
}

/// Run `stiction batch` on the long file; peak memory from /usr/bin/time if present, else by
/// polling /proc/<pid>/status.
fn run_batch(bin: &Path, long: &Path, out: &Path, threads: &str, quantify: bool) -> Run {
    let _ = std::fs::remove_dir_all(out);
    let mut args: Vec<String> = vec![
        "batch".into(),
        long.display().to_string(),
        "-o".into(),
        out.display().to_string(),
        "--sp".into(),
        "sp".into(),
        "--threads".into(),
        threads.into(),
    ];
    if !quantify {
        args.push("--no-quantify".into());
    }
    let time = Path::new("/usr/bin/time");
    let t0 = Instant::now();
    let mut cpu = None;
    // exit 3: finished, some loops failed (they are counted in the verdicts)
    let finished = |s: std::process::ExitStatus| matches!(s.code(), Some(0 | 3));
    let (ok, stderr, mut peak) = if time.exists() {
        let o = Command::new(time)
            .arg("-v")
            .arg(bin)
            .args(&args)
            .output()
            .expect("/usr/bin/time runs");
        let err = String::from_utf8_lossy(&o.stderr).into_owned();
        let peak = time_field(&err, "Maximum resident set size").map(|kb| kb as u64);
        cpu = time_field(&err, "User time")
            .zip(time_field(&err, "System time"))
            .map(|(u, s)| u + s);
        (finished(o.status), err, peak)
    } else {
        let mut child = Command::new(bin)
            .args(&args)
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .expect("the batch runs");
        let mut peak = None;
        loop {
            if let Some(kb) = vm_hwm_kb(child.id()) {
                peak = Some(kb);
            }
            if let Ok(Some(_)) = child.try_wait() {
                break;
            }
            std::thread::sleep(Duration::from_millis(50));
        }
        let o = child.wait_with_output().expect("the batch ends");
        (
            finished(o.status),
            String::from_utf8_lossy(&o.stderr).into_owned(),
            peak,
        )
    };
    let seconds = t0.elapsed().as_secs_f64();
    assert!(ok, "stiction batch failed: {stderr}");
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("summary.json")).expect("summary.json"))
            .expect("valid summary.json");
    let counts = summary["counts"]
        .as_object()
        .map(|m| {
            m.iter()
                .filter(|(_, v)| v.as_u64().unwrap_or(0) > 0)
                .map(|(k, v)| format!("{v} {k}"))
                .collect::<Vec<_>>()
                .join(", ")
        })
        .unwrap_or_default();
    if peak == Some(0) {
        peak = None;
    }
    Run {
        seconds,
        cpu,
        peak_kb: peak,
        counts,
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let value = |flag: &str| {
        args.iter()
            .position(|a| a == flag)
            .and_then(|i| args.get(i + 1).cloned())
    };
    let threads = value("--threads").unwrap_or_else(|| {
        std::thread::available_parallelism()
            .map_or(1, |n| n.get())
            .to_string()
    });
    let dir = value("--dir").map_or_else(
        || std::env::temp_dir().join("stiction-batch-scale"),
        PathBuf::from,
    );
    let keep = args.iter().any(|a| a == "--keep");
    let samples: usize = value("--samples").map_or(2000, |s| {
        s.parse().expect("--samples: a number of samples per loop")
    });
    let modes: &[bool] = if args.iter().any(|a| a == "--no-quantify-only") {
        &[false]
    } else {
        &[false, true]
    };
    let mut ns: Vec<u64> = Vec::new();
    let mut skip_next = false;
    for a in &args {
        if skip_next {
            skip_next = false;
            continue;
        }
        if a == "--threads" || a == "--dir" || a == "--samples" {
            skip_next = true;
        } else if let Ok(n) = a.parse() {
            ns.push(n);
        }
    }
    if ns.is_empty() {
        ns.push(1000);
    }
    let bin = PathBuf::from(env!("CARGO_BIN_EXE_stiction"));
    std::fs::create_dir_all(&dir).expect("the work folder");
    println!(
        "stiction batch scale: loops of {samples} samples (a quarter each: {}), {threads} threads, work folder {}",
        FAMILIES.join(", "),
        dir.display()
    );
    println!("| N | quantify | wall (s) | loops/s | CPU (s) | peak RSS (MB) | verdicts |");
    println!("|---|---|---|---|---|---|---|");
    for &n in &ns {
        let long = dir.join(format!("loops_{n}.csv"));
        let (bytes, gen_secs) = generate(&long, n, samples).expect("write the long-format file");
        eprintln!(
            "generated {n} loops: {:.0} MB in {gen_secs:.1} s ({})",
            bytes as f64 / 1e6,
            long.display()
        );
        for &quantify in modes {
            let out = dir.join(format!("out_{n}_{}", if quantify { "q" } else { "nq" }));
            let r = run_batch(&bin, &long, &out, &threads, quantify);
            println!(
                "| {n} | {} | {:.1} | {:.0} | {} | {} | {} |",
                if quantify {
                    "yes"
                } else {
                    "no (--no-quantify)"
                },
                r.seconds,
                n as f64 / r.seconds,
                r.cpu.map_or("?".into(), |c| format!("{c:.1}")),
                r.peak_kb
                    .map_or("?".into(), |kb| format!("{:.0}", kb as f64 / 1024.0)),
                r.counts
            );
            if !keep {
                let _ = std::fs::remove_dir_all(&out);
            }
        }
        if !keep {
            let _ = std::fs::remove_file(&long);
        }
    }
}

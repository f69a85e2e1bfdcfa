use crate::atomic::write_atomic;
use crate::spec;
use crate::words::count;
use anyhow::{bail, Result};
use std::path::{Path, PathBuf};
use stiction_core::sim::{simulate_open_loop, ClosedLoop, LoopData, Signal};
use stiction_core::sim_check::{loop_health, LoopHealth, Stability, SATURATION_LIMIT};

/// How the valve is driven.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
enum LoopKind {
    /// A command signal drives the valve
    Open,
    /// A PI controller drives it in a loop
    Closed,
}

#[derive(clap::Args)]
#[command(after_help = "Examples:
  stiction simulate --model stenman --param d=0.5 -o open.csv
  stiction simulate --model kano --param S=4,J=1 --signal sine:amplitude=10,period=50,offset=50 --ts 0.5 --samples 400 -o kano.csv
  stiction simulate --loop closed --model stenman --param d=0.5 --process foptd:K=3,tau=10,delay=10 \\
      --pi Kc=0.2,Ti=10 --ts 1 --samples 2000 --noise 0.05 --seed 7 -o loop.csv")]
pub struct Args {
    /// open: a command signal drives the valve; closed: a PI controller drives it in a loop
    #[arg(long = "loop", value_enum, default_value_t = LoopKind::Open)]
    loop_kind: LoopKind,
    /// Stiction model: stenman, he, kano, choudhury
    #[arg(long, default_value = "stenman")]
    model: String,
    /// Model parameters, NAME=VALUE in % of span (stenman d; he fs, fd; kano and choudhury S, J);
    /// repeat the flag or separate with commas
    #[arg(long = "param", value_name = "NAME=VALUE")]
    params: Vec<String>,
    /// Open loop: the command signal: sine|triangle:amplitude=,period=,offset= ;
    /// random-walk:std=,offset=,seed= ; steps:amplitude=,hold=,offset=,seed= ; step:from=,to=,at= ; const:value=
    /// [default: sine:amplitude=1,period=10]
    #[arg(long)]
    signal: Option<String>,
    /// Sampling time in seconds [default: 0.1 open loop, 1 closed loop]
    #[arg(long)]
    ts: Option<f64>,
    /// Number of samples [default: 1001 open loop, 2000 closed loop]
    #[arg(long)]
    samples: Option<usize>,
    /// Standard deviation of Gaussian measurement noise: on mv (open loop) or on pv (closed loop)
    #[arg(long, default_value_t = 0.0)]
    noise: f64,
    /// Seed of the noise
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Closed loop: the process, foptd:K=,tau=,delay= or integrating:K=,delay= (seconds)
    /// [default: foptd:K=3,tau=10,delay=10]
    #[arg(long)]
    process: Option<String>,
    /// Closed loop: PI controller, Kc=,Ti= (Ti in seconds) [default: Kc=0.2,Ti=10]
    #[arg(long)]
    pi: Option<String>,
    /// Closed loop: the setpoint signal (same forms as --signal) [default: step:from=50,to=51,at=10]
    #[arg(long)]
    sp: Option<String>,
    /// Closed loop: controller output and valve position at the start, % of span [default: 50]
    #[arg(long)]
    op0: Option<f64>,
    /// Closed loop: a disturbance added to pv (same forms as --signal), e.g. sine:amplitude=1,period=60
    #[arg(long)]
    disturbance: Option<String>,
    /// Output CSV with header t,sp,op,mv,pv
    #[arg(short, long)]
    output: PathBuf,
}

pub fn run(a: Args) -> Result<()> {
    let kind = spec::model_kind(&a.model)?;
    let model = spec::model(kind, &a.params)?;
    let closed = a.loop_kind == LoopKind::Closed;
    let ts = a.ts.unwrap_or(if closed { 1.0 } else { 0.1 });
    let samples = a.samples.unwrap_or(if closed { 2000 } else { 1001 });
    if !(ts > 0.0 && ts.is_finite()) {
        bail!("--ts {ts}: the sampling time must be a positive number of seconds");
    }
    if samples < 2 {
        bail!("--samples {samples}: simulate at least 2 samples");
    }
    if !(a.noise >= 0.0 && a.noise.is_finite()) {
        bail!(
            "--noise {}: the noise standard deviation must be >= 0",
            a.noise
        );
    }
    check_loop_flags(&a, closed)?;
    let data = if closed {
        let mut cl = ClosedLoop::new(model);
        cl.process = spec::process(a.process.as_deref().unwrap_or("foptd:K=3,tau=10,delay=10"))?;
        cl.pi = spec::pi(a.pi.as_deref().unwrap_or("Kc=0.2,Ti=10"))?;
        cl.setpoint = spec::signal(
            a.sp.as_deref().unwrap_or("step:from=50,to=51,at=10"),
            "--sp",
        )?;
        cl.disturbance = a
            .disturbance
            .as_deref()
            .map(|d| spec::signal(d, "--disturbance"))
            .transpose()?;
        cl.ts = ts;
        cl.samples = samples;
        cl.noise = a.noise;
        cl.seed = a.seed;
        cl.op0 = a.op0.unwrap_or(50.0);
        cl.run().map_err(|e| anyhow::anyhow!("closed loop: {e}"))?
    } else {
        let text = a.signal.as_deref().unwrap_or("sine:amplitude=1,period=10");
        let signal: Signal = spec::signal(text, "--signal")?;
        simulate_open_loop(&model, &signal, ts, samples, a.noise, a.seed)
            .map_err(|e| anyhow::anyhow!("open loop: {e}"))?
    };
    write_loop_csv(&a.output, &data)?;
    let samples_text = count(samples, "sample", "samples");
    eprintln!(
        "wrote {samples_text} ({} loop, {} {}) to {}",
        match a.loop_kind {
            LoopKind::Open => "open",
            LoopKind::Closed => "closed",
        },
        kind,
        kind.param_names()
            .iter()
            .zip(model.values())
            .map(|(n, v)| format!("{n}={v}"))
            .collect::<Vec<_>>()
            .join(" "),
        a.output.display()
    );
    if let Some(h) = loop_health(&data) {
        for w in health_warnings(&h) {
            eprintln!("warning: {}: {w}", a.output.display());
        }
    }
    Ok(())
}

/// Flags of one kind of loop given for the other are an error, not silently ignored.
fn check_loop_flags(a: &Args, closed: bool) -> Result<()> {
    let closed_only = [
        ("--process", a.process.is_some()),
        ("--pi", a.pi.is_some()),
        ("--sp", a.sp.is_some()),
        ("--op0", a.op0.is_some()),
        ("--disturbance", a.disturbance.is_some()),
    ];
    if !closed {
        if let Some((flag, _)) = closed_only.iter().find(|(_, given)| *given) {
            bail!("{flag} applies to a closed loop; add --loop closed, or leave {flag} out");
        }
    } else if a.signal.is_some() {
        bail!("--signal drives an open loop; a closed loop follows --sp (the setpoint) and --disturbance");
    }
    Ok(())
}

/// Sentences for a loop that is unstable or saturated: data of either kind says little about
/// the valve.
fn health_warnings(h: &LoopHealth) -> Vec<String> {
    let mut out = Vec::new();
    match h.stability {
        Stability::Stable => {}
        Stability::Growing => out.push(format!(
            "the loop is unstable: the control error's RMS grows {:.1}x from the second to the last quarter of the record; loosen the tuning (smaller Kc in --pi, larger Ti)",
            h.growth.unwrap_or(f64::NAN)
        )),
        Stability::RunningAway => out.push(
            "the loop is unstable: the PV runs away (beyond 1e6 or not a number); loosen the tuning (smaller Kc in --pi, larger Ti)".into(),
        ),
    }
    let swings = h.saturated_low > 0.01 && h.saturated_high > 0.01;
    if h.saturated() >= SATURATION_LIMIT && swings {
        out.push(format!(
            "OP swings between 0 and 100 % and sits at a limit {:.0} % of the time: the loop is unstable, held only by the valve's limits; loosen the tuning (smaller Kc in --pi, larger Ti)",
            100.0 * h.saturated()
        ));
    } else if h.saturated() >= SATURATION_LIMIT {
        out.push(format!(
            "OP sits at {} % {:.0} % of the time: the loop cannot reach its setpoint there; move --sp or --op0 inside the valve's range, or change the process gain",
            if h.saturated_low > h.saturated_high { 0 } else { 100 },
            100.0 * h.saturated()
        ));
    }
    out
}

/// Write `t,sp,op,mv,pv` (empty cells where a loop has no such signal), atomically
/// ([`crate::atomic`]).
pub fn write_loop_csv(path: &Path, d: &LoopData) -> Result<()> {
    let mut text = String::with_capacity(d.t.len() * 48);
    text.push_str("t,sp,op,mv,pv\n");
    let cell = |v: &[f64], i: usize| v.get(i).map(|x| format!("{x}")).unwrap_or_default();
    for i in 0..d.t.len() {
        text.push_str(&format!(
            "{},{},{},{},{}\n",
            cell(&d.t, i),
            cell(&d.sp, i),
            cell(&d.op, i),
            cell(&d.mv, i),
            cell(&d.pv, i)
        ));
    }
    write_atomic(path, text.as_bytes())
}

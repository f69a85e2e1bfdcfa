use crate::spec;
use anyhow::{bail, Context, Result};
use std::io::Write;
use std::path::{Path, PathBuf};
use stiction_core::sim::{simulate_open_loop, ClosedLoop, LoopData, Signal};

#[derive(clap::Args)]
#[command(after_help = "Examples:
  stiction simulate --model stenman --param d=0.5 -o open.csv
  stiction simulate --model kano --param S=4,J=1 --signal sine:amplitude=10,period=50,offset=50 --ts 0.5 --samples 400 -o kano.csv
  stiction simulate --loop closed --model stenman --param d=0.5 --process foptd:K=3,tau=10,delay=10 \\
      --pi Kc=0.2,Ti=10 --ts 1 --samples 2000 --noise 0.05 --seed 7 -o loop.csv")]
pub struct Args {
    /// open: a command signal drives the valve; closed: a PI controller drives it in a loop
    #[arg(long = "loop", default_value = "open", value_parser = ["open", "closed"])]
    loop_kind: String,
    /// Stiction model: stenman, he, kano, choudhury
    #[arg(long, default_value = "stenman")]
    model: String,
    /// Model parameters, NAME=VALUE in % of span (stenman d; he fs, fd; kano and choudhury S, J);
    /// repeat the flag or separate with commas
    #[arg(long = "param", value_name = "NAME=VALUE")]
    params: Vec<String>,
    /// Open loop: the command signal: sine|triangle:amplitude=,period=,offset= ;
    /// random-walk:std=,offset=,seed= ; steps:amplitude=,hold=,offset=,seed= ; step:from=,to=,at= ; const:value=
    #[arg(long, default_value = "sine:amplitude=1,period=10")]
    signal: String,
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
    #[arg(long, default_value = "foptd:K=3,tau=10,delay=10")]
    process: String,
    /// Closed loop: PI controller, Kc=,Ti= (Ti in seconds)
    #[arg(long, default_value = "Kc=0.2,Ti=10")]
    pi: String,
    /// Closed loop: the setpoint signal (same forms as --signal)
    #[arg(long, default_value = "step:from=50,to=51,at=10")]
    sp: String,
    /// Closed loop: controller output and valve position at the start, % of span
    #[arg(long, default_value_t = 50.0)]
    op0: f64,
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
    let closed = a.loop_kind == "closed";
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
    let data = if closed {
        let mut cl = ClosedLoop::new(model);
        cl.process = spec::process(&a.process)?;
        cl.pi = spec::pi(&a.pi)?;
        cl.setpoint = spec::signal(&a.sp, "--sp")?;
        cl.disturbance = a
            .disturbance
            .as_deref()
            .map(|d| spec::signal(d, "--disturbance"))
            .transpose()?;
        cl.ts = ts;
        cl.samples = samples;
        cl.noise = a.noise;
        cl.seed = a.seed;
        cl.op0 = a.op0;
        cl.run().map_err(|e| anyhow::anyhow!("closed loop: {e}"))?
    } else {
        let signal: Signal = spec::signal(&a.signal, "--signal")?;
        simulate_open_loop(&model, &signal, ts, samples, a.noise, a.seed)
            .map_err(|e| anyhow::anyhow!("open loop: {e}"))?
    };
    write_loop_csv(&a.output, &data)?;
    eprintln!(
        "wrote {} samples ({} loop, {} {}) to {}",
        samples,
        a.loop_kind,
        kind,
        kind.param_names()
            .iter()
            .zip(model.values())
            .map(|(n, v)| format!("{n}={v}"))
            .collect::<Vec<_>>()
            .join(" "),
        a.output.display()
    );
    Ok(())
}

/// Write `t,sp,op,mv,pv` (empty cells where a loop has no such signal), atomically: a temporary
/// file beside the target, then a rename.
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

pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    if let Some(dir) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("{}: cannot create the folder", dir.display()))?;
    }
    let tmp = path.with_extension(format!(
        "{}.tmp{}",
        path.extension().and_then(|e| e.to_str()).unwrap_or(""),
        std::process::id()
    ));
    let mut f = std::fs::File::create(&tmp)
        .with_context(|| format!("{}: cannot write the file", path.display()))?;
    f.write_all(bytes)
        .with_context(|| format!("{}: cannot write the file", path.display()))?;
    drop(f);
    std::fs::rename(&tmp, path)
        .with_context(|| format!("{}: cannot write the file", path.display()))
}

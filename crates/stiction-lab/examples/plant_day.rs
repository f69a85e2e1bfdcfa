//! A plant's day at plant scale: `diagnose` on day-long loops recorded at 1 s (drawn as the plant
//! windows are, one sticky valve in ten), each loop's time and verdict, then the cost against the
//! record's length for a sticky and a healthy loop (the same draws, 500 to 1,000,000 samples).
//!
//!     cargo run --release -p stiction-lab --example plant_day -- --out crates/stiction-lab/results/plant-day.md
//!
//! `--loops N` (default 30) day-long loops of `--samples S` (default 86,400); `--curve-to S` the
//! longest record of the curve (default 1,000,000); `--write DIR` also writes each day's loop as
//! `DIR/day-NNNN.csv` (columns t,sp,op,mv,pv) for whole-process timing. Times are one thread's,
//! in process (the CLI adds reading the file).

use std::fmt::Write as _;
use std::time::Instant;
use stiction_core::diagnose::{diagnose, Diagnosis, Verdict};
use stiction_lab::catalogue::{plant_day, BenchmarkLoop, Truth};
use stiction_lab::catalogue_loop::{record, request};
use stiction_lab::study_args::StudyArgs;

const CURVE: [usize; 12] = [
    500, 1_000, 2_000, 5_000, 10_000, 20_000, 43_200, 86_400, 200_000, 400_000, 700_000, 1_000_000,
];

/// Diagnose `l` `runs` times (sample by sample with `every_sample`); the fastest run's seconds and
/// the diagnosis.
fn timed(l: &BenchmarkLoop, runs: usize, every_sample: bool) -> (f64, Diagnosis) {
    let mut req = request(l);
    if every_sample {
        req.settings.averaging.min_samples = usize::MAX;
        req.settings.averaging.max_time_scales = usize::MAX;
    }
    let mut best = f64::INFINITY;
    let mut last = None;
    for _ in 0..runs {
        let t = Instant::now();
        let d = diagnose(&record(l), &req).expect("a catalogue loop is a valid record");
        best = best.min(t.elapsed().as_secs_f64());
        last = Some(d);
    }
    (best, last.expect("at least one run"))
}

fn write_csv(l: &BenchmarkLoop, path: &std::path::Path) {
    let csv = stiction_lab::catalogue_loop::csv(l);
    std::fs::write(path, csv).unwrap_or_else(|e| {
        eprintln!("plant_day: {}: cannot write: {e}", path.display());
        std::process::exit(1)
    });
}

fn verdict_name(v: Verdict) -> &'static str {
    match v {
        Verdict::Stiction => "stiction",
        Verdict::NoStiction => "no_stiction",
        Verdict::Undetermined => "undetermined",
        Verdict::InsufficientData => "insufficient_data",
    }
}

fn day_table(args: &StudyArgs, loops: usize, samples: usize, md: &mut String) {
    let dir = args.value("--write").map(std::path::PathBuf::from);
    let _ = writeln!(md, "## {loops} loops of {samples} samples at 1 s\n");
    let compare = args.has("--compare");
    md.push_str(if compare {
        "| loop | class | truth | verdict | P | judged on | seconds | every sample: verdict | P | seconds |\n|---|---|---|---|---|---|---|---|---|---|\n"
    } else {
        "| loop | class | truth | verdict | P | judged on | seconds |\n|---|---|---|---|---|---|---|\n"
    });
    let (mut moved, mut right_every) = (0, 0);
    let (mut total, mut right, mut sticky_s, mut healthy_s) = (0.0, 0, Vec::new(), Vec::new());
    for i in 0..loops {
        let l = plant_day(i, samples);
        if let Some(dir) = &dir {
            write_csv(&l, &dir.join(format!("{}.csv", l.id)));
        }
        let (s, d) = timed(&l, 1, false);
        total += s;
        let sticky = l.truth == Truth::Sticky;
        let is_right = |d: &Diagnosis| {
            usize::from(if sticky {
                d.verdict == Verdict::Stiction
            } else {
                d.verdict == Verdict::NoStiction
            })
        };
        right += is_right(&d);
        if sticky {
            sticky_s.push(s)
        } else {
            healthy_s.push(s)
        }
        let judged = d.judged_on.as_ref().map_or_else(
            || "every sample".to_string(),
            |a| format!("means of {} ({} s), {} judged", a.over, a.ts, a.samples),
        );
        let p = |d: &Diagnosis| d.probability.map_or("-".into(), |p| format!("{p:.2}"));
        let _ = write!(
            md,
            "| {} | {} | {} | {} | {} | {judged} | {s:.3} |",
            l.id,
            l.class.name(),
            l.truth.name(),
            verdict_name(d.verdict),
            p(&d),
        );
        if compare {
            let (s0, d0) = timed(&l, 1, true);
            moved += usize::from(d0.verdict != d.verdict);
            right_every += is_right(&d0);
            let _ = write!(md, " {} | {} | {s0:.3} |", verdict_name(d0.verdict), p(&d0));
        }
        md.push('\n');
        eprintln!(
            "{} {} {} {s:.3}",
            l.id,
            l.class.name(),
            verdict_name(d.verdict)
        );
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
    let _ = writeln!(
        md,
        "\nMean {:.3} s a loop ({:.3} s sticky, {:.3} s healthy); right {right} of {loops}; \
         a plant of 5,000 such loops on 2 cores: {:.1} min.{}\n",
        total / loops as f64,
        mean(&sticky_s),
        mean(&healthy_s),
        total / loops as f64 * 5000.0 / 2.0 / 60.0,
        if compare {
            format!(" Sample by sample: right {right_every} of {loops}; {moved} verdicts differ.")
        } else {
            String::new()
        }
    );
}

fn curve(to: usize, md: &mut String) {
    md.push_str("## Cost against the record's length\n\nThe same two draws (loop 0 sticky, loop 1 healthy) at every length; the fastest of three runs up to 100,000 samples, one beyond.\n\n");
    md.push_str("| samples | sticky s | judged on | healthy s | judged on | sticky / 2,000 | healthy / 2,000 |\n|---|---|---|---|---|---|---|\n");
    let mut rows = Vec::new();
    for &n in CURVE.iter().filter(|&&n| n <= to) {
        let mut row = format!("| {n} |");
        let mut secs = [0.0; 2];
        for (k, index) in [0usize, 1].into_iter().enumerate() {
            let l = plant_day(index, n);
            let (s, d) = timed(&l, if n <= 100_000 { 3 } else { 1 }, false);
            secs[k] = s;
            let judged = d
                .judged_on
                .as_ref()
                .map_or_else(|| "every sample".into(), |a| format!("means of {}", a.over));
            let _ = write!(row, " {s:.4} | {judged} ({}) |", verdict_name(d.verdict));
            eprintln!("curve {n} {index} {s:.4}");
        }
        rows.push((n, row, secs));
    }
    let base = rows
        .iter()
        .find(|r| r.0 == 2_000)
        .map_or([f64::NAN; 2], |r| r.2);
    for (_, row, secs) in rows {
        let _ = writeln!(
            md,
            "{row} {:.1} | {:.1} |",
            secs[0] / base[0],
            secs[1] / base[1]
        );
    }
}

fn main() {
    let args = StudyArgs::from_env("plant_day");
    let loops = args.number("--loops", 30);
    let samples = args.number("--samples", 86_400);
    let to = args.number("--curve-to", 1_000_000);
    let mut md = String::from("# A plant's day\n\n`cargo run --release -p stiction-lab --example plant_day`: `diagnose` (the default request, SP given, as `stiction diagnose FILE --sp sp` reads a CSV) on loops drawn as the plant windows are, recorded at 1 s, one sticky valve in ten; one thread, in process.\n\n");
    day_table(&args, loops, samples, &mut md);
    curve(to, &mut md);
    args.emit(&md);
}

//! Progress on stderr: a bar with rate and ETA on a terminal, otherwise a plain line every 5 s or
//! every 10 % (logs, CI).

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::time::{Duration, Instant};

pub struct Progress {
    bar: Option<ProgressBar>,
    start: Instant,
    last_line: Instant,
    last_tenth: u64,
    /// Loops in the batch, when known in advance (no long-format file).
    total_loops: Option<usize>,
    total_bytes: u64,
    done: usize,
    done_bytes: u64,
}

impl Progress {
    pub fn new(total_loops: Option<usize>, total_bytes: u64) -> Progress {
        let bar = std::io::stderr().is_terminal().then(|| {
            let bar = ProgressBar::with_draw_target(Some(1000), ProgressDrawTarget::stderr());
            bar.set_style(
                ProgressStyle::with_template("{bar:24.cyan/blue} {msg}")
                    .unwrap_or_else(|_| ProgressStyle::default_bar())
                    .progress_chars("=> "),
            );
            bar.enable_steady_tick(Duration::from_millis(250));
            bar
        });
        let now = Instant::now();
        Progress {
            bar,
            start: now,
            last_line: now,
            last_tenth: 0,
            total_loops,
            total_bytes,
            done: 0,
            done_bytes: 0,
        }
    }

    /// Share of the batch done: by loops when their number is known, else by bytes of input.
    fn fraction(&self) -> f64 {
        match self.total_loops {
            Some(n) if n > 0 => self.done as f64 / n as f64,
            _ if self.total_bytes > 0 => self.done_bytes as f64 / self.total_bytes as f64,
            _ => 0.0,
        }
        .min(1.0)
    }

    fn message(&self) -> String {
        let secs = self.start.elapsed().as_secs_f64();
        let rate = self.done as f64 / secs.max(1e-9);
        let f = self.fraction();
        let done = match self.total_loops {
            Some(n) => format!("{}/{n} loops", self.done),
            None => format!("{} loops, {:.0} % of the input", self.done, 100.0 * f),
        };
        let eta = if f > 0.0 && f < 1.0 {
            format!(", ETA {:.0} s", secs * (1.0 - f) / f)
        } else {
            String::new()
        };
        format!("{done}, {rate:.0} loops/s{eta}")
    }

    /// One loop finished; `weight` is the bytes of input it stood for.
    pub fn tick(&mut self, weight: u64) {
        self.done += 1;
        self.done_bytes += weight;
        let f = self.fraction();
        if let Some(bar) = &self.bar {
            bar.set_position((f * 1000.0) as u64);
            bar.set_message(self.message());
            return;
        }
        // every 5 s, or at each tenth but at most once a second (a short batch stays quiet)
        let tenth = (f * 10.0) as u64;
        let since = self.last_line.elapsed();
        if since >= Duration::from_secs(5)
            || (tenth > self.last_tenth && since >= Duration::from_secs(1))
        {
            self.last_line = Instant::now();
            self.last_tenth = tenth;
            if f < 0.995 {
                eprintln!("batch: {}", self.message());
            }
        }
    }

    /// Print a line without tearing the bar.
    pub fn println(&self, line: &str) {
        match &self.bar {
            Some(bar) => bar.suspend(|| eprintln!("{line}")),
            None => eprintln!("{line}"),
        }
    }

    pub fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}

//! A fast control loop simulated finely (0.05 s steps): a PI executed every `tc` seconds, a
//! sticky valve (any model of `stiction_core::models`) followed by a first-order actuator, a
//! process of first or second order with dead time, white measurement noise, and the look-alikes
//! of a sticky valve: an external sinusoid or narrow-band disturbance added to the PV, a setpoint
//! that moves with an outer loop (a cascade's inner loop), OP saturating. Recorded every `ts`
//! seconds, after a warm-up.

use stiction_core::models::Model;
use stiction_core::rng::{gaussian, seeded, Rng};

/// Integration step, seconds.
const H: f64 = 0.05;

/// A disturbance added to the PV, or a moving setpoint.
#[derive(Debug, Clone, Copy)]
pub enum Wave {
    None,
    /// Amplitude, period (s).
    Sine(f64, f64),
    /// Standard deviation, centre period (s), bandwidth as a share of the centre frequency: white
    /// noise through a resonant second-order filter.
    NarrowBand(f64, f64, f64),
}

#[derive(Debug, Clone)]
pub struct FastLoop {
    pub valve: Model,
    /// Actuator time constant, s (0: none).
    pub valve_lag: f64,
    /// Process gain, time constants (s; the second 0 for first order), dead time (s).
    pub k: f64,
    pub tau1: f64,
    pub tau2: f64,
    pub delay: f64,
    pub kc: f64,
    pub ti: f64,
    /// Controller period and sampling time, s.
    pub tc: f64,
    pub ts: f64,
    pub samples: usize,
    pub warmup: usize,
    pub noise: f64,
    pub disturbance: Wave,
    /// A setpoint moving with an outer loop (not recorded when it moves).
    pub setpoint: Wave,
    pub op0: f64,
    /// A load: the valve must move this far from `op0` to hold the PV at the setpoint (a
    /// sticky valve at rest then starts its cycle).
    pub load: f64,
    pub seed: u64,
}

pub struct Record {
    pub op: Vec<f64>,
    pub pv: Vec<f64>,
    pub sp: Option<Vec<f64>>,
    pub mv: Vec<f64>,
    /// Reversals of the valve's (stiction model's) moves over the record.
    pub reversals: usize,
}

/// A wave generator stepped every `H`.
struct WaveState {
    wave: Wave,
    t: f64,
    y: [f64; 2],
    a: [f64; 2],
    gain: f64,
}

impl WaveState {
    fn new(wave: Wave) -> Self {
        let (mut a, mut gain) = ([0.0; 2], 0.0);
        if let Wave::NarrowBand(sd, period, bw) = wave {
            let w = std::f64::consts::TAU * H / period;
            let r = (-0.5 * bw * w).exp();
            a = [2.0 * r * w.cos(), -r * r];
            // the stationary variance of the AR(2) for unit input, to scale it to `sd`
            let (a1, a2) = (a[0], a[1]);
            let var = (1.0 - a2) / ((1.0 + a2) * ((1.0 - a2).powi(2) - a1 * a1));
            gain = sd / var.sqrt();
        }
        Self {
            wave,
            t: 0.0,
            y: [0.0; 2],
            a,
            gain,
        }
    }

    fn step(&mut self, rng: &mut Rng) -> f64 {
        self.t += H;
        match self.wave {
            Wave::None => 0.0,
            Wave::Sine(amp, period) => amp * (std::f64::consts::TAU * self.t / period).sin(),
            Wave::NarrowBand(..) => {
                let y = self.a[0] * self.y[0] + self.a[1] * self.y[1] + gaussian(rng);
                self.y = [y, self.y[0]];
                self.gain * y
            }
        }
    }
}

impl FastLoop {
    pub fn run(&self) -> Record {
        let mut rng = seeded(self.seed);
        let steps_per_sample = (self.ts / H).round() as usize;
        let steps_per_control = (self.tc / H).round().max(1.0) as usize;
        let total = (self.samples + self.warmup) * steps_per_sample;
        let nd = (self.delay / H).round() as usize;
        let sp0 = 50.0;
        let (mut state, x0) = self.valve.start(self.op0);
        let mut fifo = vec![x0; nd + 1];
        let mut head = 0;
        let (mut x, mut x_act, mut y1, mut y2) = (x0, x0, 0.0, 0.0);
        let (mut op, mut e_prev) = (self.op0, 0.0);
        let mut dist = WaveState::new(self.disturbance);
        let mut spw = WaveState::new(self.setpoint);
        let decay = |tau: f64| if tau > 0.0 { (-H / tau).exp() } else { 0.0 };
        let (av, a1, a2) = (decay(self.valve_lag), decay(self.tau1), decay(self.tau2));
        let mut out = Record {
            op: Vec::new(),
            pv: Vec::new(),
            sp: None,
            mv: Vec::new(),
            reversals: 0,
        };
        let mut last_move = 0.0f64;
        let mut sp_rec = Vec::new();
        let moving_sp = !matches!(self.setpoint, Wave::None);
        for step in 0..total {
            let d = dist.step(&mut rng);
            let sp = sp0 + spw.step(&mut rng);
            let y = if self.tau2 > 0.0 { y2 } else { y1 };
            let pv = sp0 + y + d + self.noise * gaussian(&mut rng);
            if step % steps_per_control == 0 {
                let e = sp - pv;
                op = (op + self.kc * (e - e_prev) + self.kc * self.tc / self.ti * e)
                    .clamp(0.0, 100.0);
                e_prev = e;
                // the positioner sees each new OP once (Kano's valve reads a repeated OP as a stop)
                let x_new = self.valve.step(&mut state, op);
                let mv = x_new - x;
                if mv != 0.0 && step / steps_per_sample >= self.warmup {
                    if mv * last_move < 0.0 {
                        out.reversals += 1;
                    }
                    last_move = mv;
                }
                x = x_new;
            }
            x_act = av * x_act + (1.0 - av) * x;
            // the process sees the actuator's position `delay` ago
            fifo[head] = x_act;
            head = (head + 1) % fifo.len();
            let u = fifo[head] - x0 - self.load;
            y1 = a1 * y1 + (1.0 - a1) * self.k * u;
            y2 = a2 * y2 + (1.0 - a2) * y1;
            if step % steps_per_sample == 0 && step / steps_per_sample >= self.warmup {
                out.op.push(op);
                out.pv.push(pv);
                out.mv.push(x_act);
                sp_rec.push(sp);
            }
        }
        if !moving_sp {
            out.sp = Some(sp_rec);
        }
        out
    }

    /// The ultimate gain and period of the loop (continuous time, the controller's hold taken as
    /// half a period of delay), from the phase crossover of process, actuator and delays.
    pub fn ultimate(&self) -> (f64, f64) {
        let phase = |w: f64| {
            -(w * self.tau1).atan()
                - (w * self.tau2).atan()
                - (w * self.valve_lag).atan()
                - w * (self.delay + 0.5 * self.tc)
                - (1.0 / (w * self.ti)).atan()
        };
        let (mut lo, mut hi) = (1e-5f64, 10.0f64);
        for _ in 0..100 {
            let m = (lo * hi).sqrt();
            if phase(m) > -std::f64::consts::PI {
                lo = m;
            } else {
                hi = m;
            }
        }
        let w = lo;
        let mag = self.k
            / ((1.0 + (w * self.tau1).powi(2))
                * (1.0 + (w * self.tau2).powi(2))
                * (1.0 + (w * self.valve_lag).powi(2)))
            .sqrt()
            * (1.0 + 1.0 / (w * self.ti).powi(2)).sqrt();
        (1.0 / mag, std::f64::consts::TAU / w)
    }
}

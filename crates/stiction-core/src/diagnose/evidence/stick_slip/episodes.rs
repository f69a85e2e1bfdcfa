//! The episodes themselves: quiet stretches of PV while OP travels, each judged against the
//! look-alikes (PV not recorded, a slow process, a move against OP).

use super::{StickSlipEvidence, OP_TRAVEL_SIGMAS, PV_BAND_SIGMAS};
use crate::diagnose::oscillation::{percentile, smooth};

/// What the episode search needs besides OP and PV.
pub struct Settings<'a> {
    /// Noise standard deviation of the judged signal (PV).
    pub pv_noise: f64,
    /// Noise standard deviation of OP, OP units.
    pub op_noise: f64,
    /// The judged signal's resolution when it is quantised (the PV band is at least this).
    pub pv_quantum: Option<f64>,
    /// PV samples that look not recorded.
    pub unrecorded: &'a [bool],
    /// The PV a valve that follows OP would give (the identified linear loop), if known.
    pub pv_linear: Option<&'a [f64]>,
    /// An integrating process's rate, the judged signal's change per sample per OP unit: a
    /// level starts to move when the valve does and keeps moving, so what a valve that followed
    /// OP would have moved it by over an episode is read from OP's travel from the episode's
    /// start through the rate (which needs no load model), not from `pv_linear`.
    pub rate: Option<f64>,
    /// The process gain in units of the judged signal per OP unit; `None` when unknown.
    pub gain: Option<f64>,
    /// Process dead time, samples.
    pub dead_samples: usize,
    /// Samples the process takes to show most of a valve move (dead time and two time
    /// constants).
    pub response_samples: usize,
}

/// The slip must move the judged signal by at least this share of what the OP travel would
/// give through the process gain ...
const SLIP_SHARE: f64 = 0.3;

/// Find the stick-slip episodes of a record: `pv` is the signal judged, with `s.pv_noise` its
/// noise.
pub fn episodes(op: &[f64], pv: &[f64], s: &Settings) -> StickSlipEvidence {
    let n = op.len();
    let band = (PV_BAND_SIGMAS * s.pv_noise).max(s.pv_quantum.unwrap_or(0.0));
    let op_s = smooth(op, 5);
    let mut out = StickSlipEvidence {
        episodes: 0,
        stuck_share: 0.0,
        median_travel: None,
        median_travel_percent_of_span: None,
        pv_band: band,
        op_noise: s.op_noise,
        quiet_stretches: 0,
        skipped_unrecorded: 0,
        skipped_slow: 0,
        skipped_direction: 0,
        ranges: Vec::new(),
    };
    let (mut total, mut stuck) = (0.0, 0.0);
    let mut travels = Vec::new();
    let mut i = 0;
    while i < n {
        // the longest quiet stretch from i: PV within a band of width 2 * band
        let (mut lo, mut hi) = (pv[i], pv[i]);
        let mut j = i + 1;
        while j < n && hi.max(pv[j]) - lo.min(pv[j]) <= 2.0 * band {
            lo = lo.min(pv[j]);
            hi = hi.max(pv[j]);
            j += 1;
        }
        let net = op_s[j - 1] - op_s[i];
        total += net.abs();
        out.quiet_stretches += 1;
        if j < n && j - i >= 3 {
            match judge(op_s.as_slice(), pv, (i, j), (lo, hi), band, s) {
                Episode::Counts => {
                    out.episodes += 1;
                    stuck += net.abs();
                    travels.push(net.abs());
                    out.ranges.push([i, j]);
                }
                Episode::Unrecorded => out.skipped_unrecorded += 1,
                Episode::Slow => out.skipped_slow += 1,
                Episode::Direction => out.skipped_direction += 1,
                Episode::NoTravel => {}
            }
        }
        i = j;
    }
    out.stuck_share = if total > 0.0 { stuck / total } else { 0.0 };
    if !travels.is_empty() {
        travels.sort_by(f64::total_cmp);
        out.median_travel = Some(percentile(&travels, 0.5));
    }
    out
}

enum Episode {
    Counts,
    NoTravel,
    Unrecorded,
    Slow,
    Direction,
}

/// Does the quiet stretch `[i, j)` (PV within `[lo, hi]`) count as a stick, ended by a slip?
fn judge(
    op_s: &[f64],
    pv: &[f64],
    (i, j): (usize, usize),
    (lo, hi): (f64, f64),
    band: f64,
    s: &Settings,
) -> Episode {
    let net = op_s[j - 1] - op_s[i];
    let dir = net.signum();
    // OP travels beyond its noise, and monotonically: its largest move back is small
    let mut extreme = op_s[i];
    let mut retrace: f64 = 0.0;
    for &v in &op_s[i..j] {
        if (v - extreme) * dir > 0.0 {
            extreme = v;
        }
        retrace = retrace.max((extreme - v) * dir);
    }
    // (strictly beyond: OP that does not move at all is no travel, even without noise)
    if net.abs() <= OP_TRAVEL_SIGMAS * s.op_noise || retrace > 0.5 * net.abs() + 2.0 * s.op_noise {
        return Episode::NoTravel;
    }
    let unrecorded = s.unrecorded[i..j].iter().filter(|&&u| u).count();
    if 2 * unrecorded >= j - i {
        return Episode::Unrecorded;
    }
    // the episode must outlast the process delay, and a valve that follows OP would have moved
    // PV out of the band by its end
    if j - i <= s.dead_samples + 1 {
        return Episode::Slow;
    }
    let followed = match (s.rate, s.pv_linear) {
        (Some(rate), _) => Some(
            op_s[i..j]
                .iter()
                .scan(0.0, |level, v| {
                    *level += rate * (v - op_s[i]);
                    Some(level.abs())
                })
                .fold(0.0, f64::max),
        ),
        (None, Some(lin)) => Some(
            lin[i..j]
                .iter()
                .map(|v| (v - lin[i]).abs())
                .fold(0.0, f64::max),
        ),
        (None, None) => None,
    };
    if followed.is_some_and(|moved| moved < 2.0 * band) {
        return Episode::Slow;
    }
    // the slip: within the process's response time PV leaves the band the way OP pushed it, by
    // a good share of what the OP travel gives through the process gain (a loop that holds PV
    // against a disturbance moves OP as much, but PV does not then catch up)
    let end = (j + s.response_samples.max(3)).min(pv.len());
    let level = 0.5 * (lo + hi);
    let sign = s.gain.map_or(1.0, f64::signum);
    let expected = dir * sign;
    let moved = pv[j..end]
        .iter()
        .map(|v| (v - level) * expected)
        .fold(f64::NEG_INFINITY, f64::max);
    let needed = s
        .gain
        .map_or(0.0, |g| SLIP_SHARE * (g * net).abs())
        .max(band);
    if moved >= needed {
        Episode::Counts
    } else {
        Episode::Direction
    }
}

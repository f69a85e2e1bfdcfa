//! The stick-slip family: a sticky valve that does not limit-cycle still shows itself as episodes
//! in which OP travels (the integral action winding up) while PV stays inside its noise band, ended
//! by a PV move in OP's direction when the valve breaks free (Kano et al. 2004's "stick, then
//! jump"; Damarla et al. 2022/2023 test windows for "PV steady while OP changes"). The OP travel per
//! stick is a model-free estimate of the band.
//!
//! Windows in which PV is steady while OP changes are common in healthy loops too, so an episode
//! counts only when it cannot be one of the look-alikes:
//! - PV not recorded (historian compression, a frozen transmitter): runs of repeated values or
//!   exactly straight lines are not "PV steady";
//! - quantised PV: the band is at least one quantum;
//! - a slow process or a long delay: the identified linear loop, driven by the same OP through a
//!   valve that follows it, must predict that PV would have left the band within the episode;
//! - the ending PV move must go the way OP pushed (through the process gain's sign).

use super::{Context, EvidenceFamily, Family, FamilyEvidence};
use crate::diagnose::gates::plural;
use crate::diagnose::oscillation::{percentile, smooth};
use crate::diagnose::result::Vote;
use serde::{Deserialize, Serialize};

/// The stick-slip family.
pub struct StickSlip;

/// Half-width of the PV's noise band, in noise standard deviations.
pub const PV_BAND_SIGMAS: f64 = 2.5;
/// OP must travel more than this many of its noise standard deviations in an episode.
pub const OP_TRAVEL_SIGMAS: f64 = 4.0;
/// Strength of a stiction vote: below what a verdict needs on its own (see the verdict).
const STICTION_STRENGTH: f64 = 0.4;
/// From this many episodes holding at least [`DECISIVE_SHARE`] of the OP's travel the vote is
/// held with [`DECISIVE_STRENGTH`], enough to decide alone. On the catalogue's calibration set and
/// nine more draws of it (3,600 not-sticky loops, 3,300 sticky ones, 300 backlash valves), no
/// not-sticky loop with 20 episodes or more spends more than 66 % of the OP's travel in them (the
/// highest: an equal-percentage valve, 66 %, a saturating OP, 64 %, an external oscillation,
/// 62 %); 36 sticky loops and 1 backlash valve reach 20 episodes holding 70 % or more.
pub const DECISIVE_EPISODES: usize = 20;
/// See [`DECISIVE_EPISODES`].
pub const DECISIVE_SHARE: f64 = 0.7;
/// Strength of a stiction vote from [`DECISIVE_EPISODES`] episodes: above the verdict's need.
const DECISIVE_STRENGTH: f64 = 0.6;
/// Episodes at and above which the family votes stiction ...
pub const MIN_EPISODES: usize = 5;
/// ... when at least this share of the OP's travel was spent stuck.
pub const MIN_STUCK_SHARE: f64 = 0.5;
/// At most this many episodes, with at least this share of OP travel ...
pub const MAX_EPISODES_NONE: usize = 1;
/// ... over at least this many quiet stretches, vote against stiction ...
pub const MIN_STRETCHES_NONE: usize = 10;
/// ... in a record of at least this many samples (a short record shows few sticks either way).
pub const MIN_SAMPLES_NONE: usize = 400;

/// What the episodes show.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StickSlipEvidence {
    /// Episodes that count: OP travelled, PV stayed, then PV moved OP's way.
    pub episodes: usize,
    /// Share of the OP's travel spent in them.
    pub stuck_share: f64,
    /// Median OP travel per episode: a model-free band estimate, OP units and % of span.
    pub median_travel: Option<f64>,
    /// The same, % of valve span.
    pub median_travel_percent_of_span: Option<f64>,
    /// The PV band's half-width (PV units) and the OP noise (OP units) the episodes are held to.
    pub pv_band: f64,
    /// The OP noise standard deviation, OP units.
    pub op_noise: f64,
    /// Quiet stretches of PV the record was cut into.
    pub quiet_stretches: usize,
    /// Look-alikes left out: PV not recorded; a healthy valve would not have moved PV yet; PV
    /// moved against OP's push.
    pub skipped_unrecorded: usize,
    /// Episodes left out because a healthy valve would not have moved PV yet (a slow process or a
    /// long delay).
    pub skipped_slow: usize,
    /// Episodes left out because PV moved against OP's push.
    pub skipped_direction: usize,
    /// The episodes, as sample ranges `[start, end)` of the analysed stretch.
    pub ranges: Vec<[usize; 2]>,
}

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
pub const SLIP_SHARE: f64 = 0.3;

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

/// The family's vote on its episodes (over a record of `samples`), its strength and why.
fn ballot(e: &StickSlipEvidence, samples: usize) -> (Vote, f64, String) {
    if e.episodes >= MIN_EPISODES && e.stuck_share >= MIN_STUCK_SHARE {
        let decisive = e.episodes >= DECISIVE_EPISODES && e.stuck_share >= DECISIVE_SHARE;
        (
            Vote::Stiction,
            // corroborating evidence only, unless the episodes are many and hold most of the
            // OP's travel: on the calibration set, a few episodes alone called too many healthy
            // loops that hold PV against a load sticky
            if decisive {
                DECISIVE_STRENGTH
            } else {
                STICTION_STRENGTH
            },
            format!(
                "{} episodes of OP travelling while PV stayed put, then PV jumped OP's way ({:.0} % of the OP's travel; median {:.2} % of span per stick){}",
                e.episodes,
                100.0 * e.stuck_share,
                e.median_travel_percent_of_span.unwrap_or(0.0),
                if decisive {
                    ": so many, holding so much of the OP's travel, that healthy loops do not give it"
                } else {
                    ""
                }
            ),
        )
    } else if e.episodes <= MAX_EPISODES_NONE
        && e.quiet_stretches >= MIN_STRETCHES_NONE
        && samples >= MIN_SAMPLES_NONE
    {
        (
            Vote::NoStiction,
            0.25,
            format!(
                "{} in {} of quiet PV: PV follows OP",
                plural(e.episodes, "stick-slip episode", "stick-slip episodes"),
                plural(e.quiet_stretches, "stretch", "stretches")
            ),
        )
    } else if e.episodes >= MIN_EPISODES {
        (
            Vote::Undetermined,
            0.0,
            format!(
                "{} episodes in {}, but they hold only {:.0} % of the OP's travel: a vote needs {:.0} %",
                e.episodes,
                plural(e.quiet_stretches, "quiet stretch", "quiet stretches"),
                100.0 * e.stuck_share,
                100.0 * MIN_STUCK_SHARE
            ),
        )
    } else {
        (
            Vote::Undetermined,
            0.0,
            format!(
                "{} ({:.0} % of the OP's travel) in {}: too few to decide (a vote needs {MIN_EPISODES})",
                plural(e.episodes, "episode", "episodes"),
                100.0 * e.stuck_share,
                plural(e.quiet_stretches, "quiet stretch", "quiet stretches")
            ),
        )
    }
}

impl EvidenceFamily for StickSlip {
    fn family(&self) -> Family {
        Family::StickSlip
    }

    fn evaluate(&self, ctx: &Context) -> FamilyEvidence {
        let statistic = "episodes of OP travelling while PV stays inside its noise band, ended by a PV move OP's way";
        let threshold = format!(
            "stiction from {MIN_EPISODES} episodes holding {:.0} % of the OP's travel (decisive from {DECISIVE_EPISODES} holding {:.0} %); none with at most {MAX_EPISODES_NONE} over {MIN_STRETCHES_NONE} or more quiet stretches \
             (OP beyond {OP_TRAVEL_SIGMAS} noise standard deviations, PV within ±{PV_BAND_SIGMAS})",
            100.0 * MIN_STUCK_SHARE,
            100.0 * DECISIVE_SHARE
        );
        let ts = ctx.req.ts;
        let found = |g: Option<f64>| g.filter(|g| g.is_finite() && *g != 0.0);
        let (pv_linear, rate, gain, dead_samples, response_samples) = match &ctx.fits {
            // a level (its fit's gain a rate per second): what a valve step moves it by over the
            // lag the fits compare (1.5 response times, at least a 25th of the record), a window
            // the slip's move must show within
            Some(f) if f.structure.integrating => (
                None,
                found(f.gain).map(|k| k * ts),
                found(f.gain).map(|k| k * f.lag as f64 * ts),
                (f.dead_time / ts).round() as usize,
                f.lag,
            ),
            Some(f) => (
                (!f.pv_linear.is_empty()).then_some(f.pv_linear.as_slice()),
                None,
                found(f.gain),
                (f.dead_time / ts).round() as usize,
                ((f.dead_time + 2.0 * f.time_constant.unwrap_or(0.0)) / ts).round() as usize + 1,
            ),
            None => (None, None, None, 0, 3),
        };
        // Every loop is judged on PV itself, levels too: a stuck level valve leaves the level
        // still where the flows nearly balance. Judging a level's smoothed rate instead (which a
        // stuck valve holds) was measured on the plant benchmark's calibration set, with the
        // rate's noise carried through the smoothing: no more sticky loops found, more healthy
        // ones left undetermined (balanced accuracy 0.627 to 0.620).
        let settings = Settings {
            pv_noise: ctx.pv_noise,
            op_noise: ctx.op_noise,
            pv_quantum: ctx.pv_quantum,
            unrecorded: &ctx.unrecorded,
            pv_linear,
            rate,
            gain,
            dead_samples,
            response_samples,
        };
        let mut e = episodes(ctx.op, ctx.pv, &settings);
        e.median_travel_percent_of_span = e.median_travel.map(|t| ctx.req.percent_of_span(t));
        let (vote, strength, why) = ballot(&e, ctx.op.len());
        // enough episodes that hold too little of the OP's travel: evidence, too weak to decide
        let leans =
            (vote == Vote::Undetermined && e.episodes >= MIN_EPISODES).then_some(Vote::Stiction);
        let skipped = e.skipped_unrecorded + e.skipped_slow + e.skipped_direction;
        let note = if skipped > 0 {
            format!(
                "{why}; left out as look-alikes: {} with PV not recorded, {} a healthy valve would also give (slow process), {} with PV moving against OP",
                e.skipped_unrecorded, e.skipped_slow, e.skipped_direction
            )
        } else {
            why
        };
        FamilyEvidence {
            family: Family::StickSlip,
            vote,
            strength,
            value: Some(e.episodes as f64),
            statistic: statistic.into(),
            threshold,
            note,
            leans,
            model: None,
            stick_slip: Some(e),
            valve: None,
            limit_cycle: None,
            hidden_valve: None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn settings(unrecorded: &[bool]) -> Settings<'_> {
        Settings {
            pv_noise: 0.01,
            op_noise: 0.01,
            pv_quantum: None,
            unrecorded,
            pv_linear: None,
            rate: None,
            gain: Some(1.0),
            dead_samples: 2,
            response_samples: 3,
        }
    }

    /// OP ramps 1 unit over 20 samples while PV holds, then PV steps up: repeated 5 times.
    fn stick_slip_record() -> (Vec<f64>, Vec<f64>) {
        sticks(5)
    }

    /// OP ramps 1 unit over 20 samples while PV holds, then PV steps up: repeated `n` times.
    fn sticks(n: usize) -> (Vec<f64>, Vec<f64>) {
        let mut op = Vec::new();
        let mut pv = Vec::new();
        let mut level = 0.0;
        for _ in 0..n {
            for k in 0..20 {
                op.push(level + k as f64 / 20.0);
                pv.push(level);
            }
            level += 1.0;
        }
        (op, pv)
    }

    #[test]
    fn stick_then_slip_is_counted_with_its_travel() {
        let (op, pv) = stick_slip_record();
        let unrecorded = vec![false; op.len()];
        let e = episodes(&op, &pv, &settings(&unrecorded));
        assert_eq!(e.episodes, 4, "{e:?}");
        // OP travels 0.95 in each stick
        let t = e.median_travel.unwrap();
        assert!((t - 0.95).abs() < 0.1, "{t}");
        assert!(e.stuck_share > 0.7);
    }

    #[test]
    fn many_episodes_holding_most_of_the_travel_decide_a_few_only_corroborate() {
        let vote = |n: usize| {
            let (op, pv) = sticks(n);
            let unrecorded = vec![false; op.len()];
            let e = episodes(&op, &pv, &settings(&unrecorded));
            assert!(e.stuck_share >= DECISIVE_SHARE, "{e:?}");
            (e.episodes, ballot(&e, op.len()))
        };
        let (few, (v, strength, _)) = vote(8);
        assert!(few < DECISIVE_EPISODES);
        assert_eq!(v, Vote::Stiction);
        assert_eq!(strength, STICTION_STRENGTH);
        let (many, (v, strength, why)) = vote(DECISIVE_EPISODES + 2);
        assert!(many >= DECISIVE_EPISODES, "{many}");
        assert_eq!(v, Vote::Stiction);
        assert_eq!(strength, DECISIVE_STRENGTH);
        assert!(why.contains("healthy loops do not give it"), "{why}");
    }

    #[test]
    fn pv_that_was_not_recorded_is_no_episode() {
        let (op, pv) = stick_slip_record();
        let unrecorded = vec![true; op.len()];
        let e = episodes(&op, &pv, &settings(&unrecorded));
        assert_eq!(e.episodes, 0);
        assert_eq!(e.skipped_unrecorded, 4);
    }

    #[test]
    fn a_pv_move_against_op_is_no_episode() {
        let (op, pv) = stick_slip_record();
        let unrecorded = vec![false; op.len()];
        let s = Settings {
            gain: Some(-1.0),
            ..settings(&unrecorded)
        };
        let e = episodes(&op, &pv, &s);
        assert_eq!(e.episodes, 0);
        assert_eq!(e.skipped_direction, 4);
    }
}

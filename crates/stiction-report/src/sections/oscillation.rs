//! The oscillation's figures.

use super::*;

pub fn oscillation(d: &Diagnosis) -> Option<Vec<KvRow>> {
    let o = d.oscillation.as_ref()?;
    let r = &o.regularity;
    let said = if o.oscillating && o.weak_cycle {
        format!(
            "yes: a weak cycle, regular and 1.5 to 3 noise standard deviations high; its period wanders as a limit cycle's does beside noise (one that kept a clock's time would be an input's){}",
            if o.across_setpoint_steps {
                "; across the setpoint's steps (no hold is long enough)"
            } else {
                ""
            }
        )
    } else if o.oscillating && o.across_setpoint_steps {
        "yes: regular and above the noise, across the setpoint's steps (no hold is long enough)"
            .to_string()
    } else if o.oscillating {
        "yes: regular and above the noise".to_string()
    } else {
        "no".into()
    };
    Some(vec![
        kv(
            "Oscillating",
            match o.reading_words() {
                Some(w) => format!("{said} ({w})"),
                None => said,
            },
        ),
        kv("Period", o.period.map_or("–".into(), duration)),
        kv("Periods in the analysed stretch", opt(o.periods_in_record)),
        kv(
            "Share of the error's variance in the cycle",
            o.cycle_share.map_or("–".into(), |c| format!("{:.0} %", 100.0 * c.max(0.0))),
        ),
        kv(
            "Regularity (Thornhill)",
            format!(
                "{} (regular above {}; {} zero crossings of the autocorrelation)",
                r.shown(),
                num(r.threshold),
                r.zero_crossings
            ),
        ),
        kv(
            "Half periods with a large IAE (Hägglund)",
            format!(
                "{} in the record, at most {} in one supervision window of {} (limit {}; IAE limit {})",
                o.iae.exceedances,
                o.iae.most_in_window,
                duration(o.iae.window),
                o.iae.n_lim,
                num(o.iae.iae_limit)
            ),
        ),
        kv(
            "Amplitude of the control error",
            format!("{} (half the 5 %–95 % range)", num(o.amplitude)),
        ),
        kv("Noise standard deviation", num(o.noise_std)),
    ])
}

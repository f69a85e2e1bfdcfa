//! The compared fits put in words and R²: what `compare_fits` returns.

use super::{dependence, CompareRequest, FitComparison, ModelFit, Setup};
use crate::detect::measurement_noise;
use crate::identify::{self, Data, Fit};
use crate::models::Model;
use crate::quantify::problem::difference;

/// The compared fits, before they are put in words and R².
pub(super) struct Fits {
    pub(super) linear: Option<Fit>,
    pub(super) stenman: (Model, f64),
    pub(super) slip_jump: (Model, f64),
    /// The better of the two stiction models, and its linear part.
    pub(super) stiction: Model,
    pub(super) stiction_fit: Fit,
    pub(super) x0: f64,
    pub(super) samples_used: usize,
    pub(super) evaluations: u64,
}

impl Fits {
    pub(super) fn into_comparison(
        self,
        op: &[f64],
        pv: &[f64],
        setup: &Setup,
        req: &CompareRequest,
    ) -> FitComparison {
        let fit_s = self.stiction_fit;
        let sst = fit_s.sst;
        let phys = identify::physical(&fit_s, req.ts);
        let levels = Data::new(pv, setup.t0);
        let mv_stiction = self.stiction.simulate_from(op, Some(self.x0));
        let mv_centred: Vec<f64> = mv_stiction.iter().map(|v| v - setup.offset).collect();
        let pv_stiction = identify::simulate_pv(&levels, &mv_centred, &fit_s);
        let pv_linear = self
            .linear
            .as_ref()
            .map(|f| identify::simulate_pv(&levels, &setup.op_centred, f))
            .unwrap_or_default();
        let r2 = |sse: f64| 1.0 - sse / sst;
        let linear_sse = self
            .linear
            .as_ref()
            .map_or(sst, |f| f.sse_simulation.min(sst));
        // the compared output's noise: white noise differenced over the lag (twice again for an
        // integrating structure's change)
        let sigma = measurement_noise(pv);
        let compared = Data::new(&setup.y, setup.t0);
        let mv_compared = {
            let mut mv = vec![0.0; op.len() - setup.lag];
            difference(&mv_stiction, setup.lag, &mut mv);
            mv
        };
        let correlation_span = dependence::correlation_span(
            &compared,
            setup.lag,
            (&mv_compared, &fit_s),
            self.linear
                .as_ref()
                .map(|f| (setup.linear_mv.as_slice(), f)),
        );
        FitComparison {
            correlation_span,
            structure: fit_s.structure,
            lag: setup.lag,
            samples_used: self.samples_used,
            sst,
            noise_var: 2.0 * sigma * sigma,
            valve_start: self.x0,
            linear: ModelFit {
                params: Vec::new(),
                sse: linear_sse,
                r2: r2(linear_sse),
            },
            stenman: ModelFit {
                params: vec![self.stenman.0.values()[0]],
                sse: self.stenman.1,
                r2: r2(self.stenman.1),
            },
            slip_jump: ModelFit {
                params: stiction_params(&self.slip_jump.0),
                sse: self.slip_jump.1,
                r2: r2(self.slip_jump.1),
            },
            gain: phys.gain,
            time_constant: phys.time_constant,
            dead_time: phys.dead_time,
            evaluations: self.evaluations,
            pv_linear,
            pv_stiction,
            mv_stiction,
            linear_model: self.linear,
            stiction_model: Some(fit_s),
            op_offset: setup.offset,
        }
    }
}

fn stiction_params(m: &Model) -> Vec<f64> {
    match m {
        // Stenman's valve as a slip-jump model: S = J = d
        Model::Stenman(s) => vec![s.d, s.d],
        other => other.values(),
    }
}

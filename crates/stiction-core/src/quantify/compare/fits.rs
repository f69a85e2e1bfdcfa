//! The compared fits put in words and R²: what `compare_fits` returns.

use super::{dependence, CompareRequest, FitComparison, ModelFit, Setup};
use crate::detect::measurement_noise;
use crate::identify::{self, Data, Fit};
use crate::models::Model;
use crate::quantify::problem::{over_lag, OverLag};

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
        let stiction_model = per_sample(&fit_s, setup);
        let linear_model = self.linear.as_ref().map(|f| per_sample(f, setup));
        let phys = identify::physical(&stiction_model, req.ts);
        let levels = Data::new(pv, setup.t0);
        let mv_stiction = self.stiction.simulate_from(op, Some(self.x0));
        let mv_centred: Vec<f64> = mv_stiction.iter().map(|v| v - setup.offset).collect();
        let pv_stiction = identify::simulate_pv(&levels, &mv_centred, &stiction_model);
        let pv_linear = linear_model
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
            over_lag(&mv_stiction, setup.lag, setup.over, setup.offset, &mut mv);
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
            structure: stiction_model.structure,
            over_lag: setup.over,
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
            linear_model,
            stiction_model: Some(stiction_model),
            op_offset: setup.offset,
        }
    }
}

/// A fit of the compared changes as the model of the PV it implies: as it is for the valve's
/// change over the lag (the same dynamics), and for its sum over the lag the integrating
/// structure of the PV's change per sample, one sample more delay (`A(q)(q^L - 1) pv =
/// B(q) q^-nk (q^L - 1) q^-1 / (1 - q^-1) x`, so `A(q) (1 - q^-1) pv = B(q) q^-(nk+1) x`), its
/// constant a sample's share of the lag's.
fn per_sample(f: &Fit, setup: &Setup) -> Fit {
    match setup.over {
        OverLag::Change => f.clone(),
        OverLag::Sum => Fit {
            structure: identify::Structure {
                integrating: true,
                nk: f.structure.nk + 1,
                ..f.structure
            },
            c: f.c / setup.lag as f64,
            ..f.clone()
        },
    }
}

fn stiction_params(m: &Model) -> Vec<f64> {
    match m {
        // Stenman's valve as a slip-jump model: S = J = d
        Model::Stenman(s) => vec![s.d, s.d],
        other => other.values(),
    }
}

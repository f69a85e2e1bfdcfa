//! What `quantify` is asked to do.

use crate::checked::Checked;
use crate::estimate::{self, AcoSettings, AcorSettings, EstimateError, GridSettings, Method};
use crate::models::ModelKind;
use serde::{Deserialize, Serialize};

/// A closed-loop quantification request: the stiction model, the search method and its
/// settings, and the linear model search.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct QuantifyRequest {
    /// The stiction model to fit.
    pub model: ModelKind,
    /// The search method for its parameters.
    pub method: Method,
    /// Sampling time in seconds (for the time constant and dead time).
    pub ts: f64,
    /// Search range per stiction parameter; `None`: 0 up to the OP's peak-to-peak range.
    pub bounds: Option<Vec<(f64, f64)>>,
    /// Seed of the random searches (aco, aco-r).
    pub seed: u64,
    /// Settings of the paper's ACO.
    pub aco: AcoSettings,
    /// Settings of ACO_R.
    pub acor: AcorSettings,
    /// Settings of the grid search (points per parameter).
    pub grid: GridSettings,
    /// Largest delay tried, in samples.
    pub max_delay: usize,
    /// `Some(true)`: integrating process only; `Some(false)`: self-regulating only; `None`: both.
    pub integrating: Option<bool>,
    /// Stenman exact: fit every cell of the whole d-range, not only those around the best scan points.
    pub full_partition: bool,
    /// Stenman exact on long records: search the whole d-range on the first samples, then only
    /// the best cells of that search on the whole record (every whole-record cell lies inside one
    /// cell of the first samples', so this is exact over the cells kept). `false`: every cell of
    /// the whole record.
    pub staged: bool,
    /// The valve position at the first sample (Stenman and He); `None`: where OP starts, as if
    /// the valve had just moved there (unless `estimate_start` chooses one).
    #[serde(default)]
    pub valve_start: Option<f64>,
    /// Stenman exact: choose the valve position at the first sample (a record rarely starts just
    /// as the valve moved) among candidates across the OP's span, by the fit on the first samples.
    /// Off by default: it costs about four more searches of the first samples.
    #[serde(default)]
    pub estimate_start: bool,
}

impl QuantifyRequest {
    /// A request for `model` by `method` with the defaults: ts 1 s, seed 1, a 40-point grid, 60
    /// ACO_R iterations, delays up to 30 samples, both process families, the full partition
    /// staged on long records, the valve starting where OP does.
    pub fn new(model: ModelKind, method: Method) -> Self {
        let grid = GridSettings { points: 40 };
        Self {
            model,
            method,
            ts: 1.0,
            bounds: None,
            seed: 1,
            aco: AcoSettings::default(),
            acor: AcorSettings {
                iterations: 60,
                ..AcorSettings::default()
            },
            grid,
            max_delay: 30,
            integrating: None,
            full_partition: true,
            staged: true,
            valve_start: None,
            estimate_start: false,
        }
    }

    /// Check the request once, before any data are read: the sampling time, the search method's
    /// settings (as [`estimate::Request::check`] does: an ant count of 0 is an error naming the
    /// setting, not a failed search), the exact method asked for Stenman only, the search range
    /// when one is given, and the valve's start position. [`super::quantify_checked`] runs the
    /// checked request without checking it again.
    pub fn check(&self) -> Result<Checked<QuantifyRequest>, EstimateError> {
        if !(self.ts > 0.0 && self.ts.is_finite()) {
            return Err(EstimateError::Ts(self.ts));
        }
        let mut settings = estimate::Request::new(self.model, self.method);
        settings.aco = self.aco.clone();
        settings.acor = self.acor.clone();
        settings.grid = self.grid.clone();
        settings.check_settings()?;
        if let Some(bounds) = &self.bounds {
            estimate::check_bounds(self.model, bounds)?;
        }
        if let Some(x0) = self.valve_start.filter(|x| !x.is_finite()) {
            return Err(EstimateError::ValveStart(x0));
        }
        Ok(Checked::new(self.clone()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn check_finds_each_kind_of_mistake() {
        let good = QuantifyRequest::new(ModelKind::Stenman, Method::Exact);
        assert_eq!(*good.check().unwrap(), good);
        let mut r = good.clone();
        r.ts = 0.0;
        assert_eq!(r.check().unwrap_err(), EstimateError::Ts(0.0));
        let mut r = good.clone();
        r.bounds = Some(vec![(-1.0, 1.0)]);
        assert!(matches!(r.check(), Err(EstimateError::Bounds { .. })));
        let mut r = good.clone();
        r.valve_start = Some(f64::INFINITY);
        assert!(matches!(r.check(), Err(EstimateError::ValveStart(x)) if x.is_infinite()));
        let mut r = QuantifyRequest::new(ModelKind::He, Method::AcoR);
        r.acor.archive = 1;
        assert!(matches!(
            r.check(),
            Err(EstimateError::Setting {
                method: Method::AcoR,
                name: "archive",
                ..
            })
        ));
        let r = QuantifyRequest::new(ModelKind::He, Method::Exact);
        assert_eq!(
            r.check().unwrap_err(),
            EstimateError::ExactNeedsStenman(ModelKind::He)
        );
    }
}

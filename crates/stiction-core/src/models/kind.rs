//! The run-time choice of model: its name and its parameters' names and bounds.

use super::*;

/// Which model, chosen at run time (from a command line or a config).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ModelKind {
    /// Stenman's one-parameter model (band d).
    Stenman,
    /// He et al.'s model (static band fs, kinetic band fd).
    He,
    /// Kano et al.'s model (S, J).
    Kano,
    /// Choudhury et al.'s model (S, J).
    Choudhury,
}

const STENMAN_PARAMS: [ParamSpec; 1] = [ParamSpec {
    name: "d",
    unit: "% of span",
    description: "stiction band",
    min: 0.0,
    search: (0.01, 10.0),
}];
const HE_PARAMS: [ParamSpec; 2] = [
    ParamSpec {
        name: "fs",
        unit: "% of span",
        description: "static friction band",
        min: 0.0,
        search: (0.0, 10.0),
    },
    ParamSpec {
        name: "fd",
        unit: "% of span",
        description: "kinetic friction band, at most fs",
        min: 0.0,
        search: (0.0, 10.0),
    },
];
const KANO_PARAMS: [ParamSpec; 2] = [
    ParamSpec {
        name: "S",
        unit: "% of span",
        description: "deadband plus stickband",
        min: 0.0,
        search: (0.0, 10.0),
    },
    ParamSpec {
        name: "J",
        unit: "% of span",
        description: "slip jump",
        min: 0.0,
        search: (0.0, 10.0),
    },
];

impl ModelKind {
    /// Every model.
    pub const ALL: [ModelKind; 4] = [Self::Stenman, Self::He, Self::Kano, Self::Choudhury];

    /// The model's name, as the CLI and serde write it (`stenman`).
    pub fn name(self) -> &'static str {
        match self {
            Self::Stenman => "stenman",
            Self::He => "he",
            Self::Kano => "kano",
            Self::Choudhury => "choudhury",
        }
    }

    /// The model's parameters, in order.
    pub fn params(self) -> &'static [ParamSpec] {
        match self {
            Self::Stenman => &STENMAN_PARAMS,
            Self::He => &HE_PARAMS,
            Self::Kano | Self::Choudhury => &KANO_PARAMS,
        }
    }

    /// Number of parameters.
    pub fn dim(self) -> usize {
        self.params().len()
    }

    /// Index of a parameter by name (case-insensitive), or a clear error.
    pub fn param_index(self, name: &str) -> Result<usize, ModelError> {
        self.params()
            .iter()
            .position(|p| p.name.eq_ignore_ascii_case(name))
            .ok_or_else(|| ModelError::UnknownParameter {
                model: self.name(),
                name: name.to_string(),
                known: self.param_names().join(", "),
            })
    }

    /// The parameters' names, in order.
    pub fn param_names(self) -> Vec<&'static str> {
        self.params().iter().map(|p| p.name).collect()
    }

    /// Build a validated model from parameter values in the order of [`ModelKind::params`].
    pub fn build(self, values: &[f64]) -> Result<Model, ModelError> {
        assert_eq!(values.len(), self.dim());
        Ok(match self {
            Self::Stenman => Model::Stenman(Stenman::new(values[0])?),
            Self::He => Model::He(He::new(values[0], values[1])?),
            Self::Kano => Model::Kano(Kano::new(values[0], values[1])?),
            Self::Choudhury => Model::Choudhury(Choudhury::new(values[0], values[1])?),
        })
    }

    /// Make a candidate from a search valid in place (He: fd <= fs). Estimators call this on every
    /// candidate they draw so the search space is the feasible set.
    pub fn repair(self, values: &mut [f64]) {
        for (v, p) in values.iter_mut().zip(self.params()) {
            if *v < p.min {
                *v = p.min;
            }
        }
        if self == Self::He && values[1] > values[0] {
            values[1] = values[0];
        }
    }
}

impl fmt::Display for ModelKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for ModelKind {
    type Err = ModelError;
    fn from_str(s: &str) -> Result<Self, ModelError> {
        Self::ALL
            .into_iter()
            .find(|k| k.name().eq_ignore_ascii_case(s.trim()))
            .ok_or_else(|| ModelError::UnknownModel(s.to_string()))
    }
}

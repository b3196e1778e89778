//! The models the study compares ([`Model`]) and the hybrid's law.

use palpate_kernel::tensor_mass::{ElasticLaw, StvkForm};
use serde::Serialize;

use super::body::Body;
use crate::fem::penalty::penalty_n;

/// The models compared.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Model {
    /// Pre-computed linear (linear FEM).
    PrecomputedLinear,
    /// Pre-computed with the quasi-non-linear remap.
    PrecomputedQuasi,
    /// Tensor-mass, linear law.
    TensorMassLinear,
    /// Tensor-mass, St Venant-Kirchhoff.
    Stvk,
    /// Tensor-mass, St Venant-Kirchhoff + incompressibility penalty.
    StvkPenalty,
    /// Tensor-mass, co-rotational linear (stiffness warping).
    Corotational,
    /// Tensor-mass, compressible neo-Hookean (the truth's law).
    NeoHookean,
    /// The hybrid (RR-3510 §6.2): St Venant-Kirchhoff tensor-mass in the
    /// region at the loaded end ([`Body::hybrid_dynamic_tets`]), the rest
    /// pre-computed linear, condensed onto the connection nodes.
    Hybrid,
}

impl Model {
    /// Every model, cheapest family first.
    pub const ALL: [Model; 8] = [
        Model::PrecomputedLinear,
        Model::PrecomputedQuasi,
        Model::TensorMassLinear,
        Model::Stvk,
        Model::StvkPenalty,
        Model::Corotational,
        Model::NeoHookean,
        Model::Hybrid,
    ];

    /// The tensor-mass law and incompressibility penalty (N) of the model
    /// on `body`; `None` for the pre-computed models and the hybrid.
    pub fn tensor_mass(self, body: &Body) -> Option<(ElasticLaw, Option<f64>)> {
        let stvk = ElasticLaw::StVenantKirchhoff(StvkForm::PerTet);
        match self {
            Model::PrecomputedLinear | Model::PrecomputedQuasi | Model::Hybrid => None,
            Model::TensorMassLinear => Some((ElasticLaw::Linear, None)),
            Model::Stvk => Some((stvk, None)),
            Model::StvkPenalty => Some((stvk, Some(penalty_n(&body.mesh, &body.material)))),
            Model::Corotational => Some((ElasticLaw::Corotational, None)),
            Model::NeoHookean => Some((ElasticLaw::NeoHookean, None)),
        }
    }

    /// A tensor-mass model (relaxed, integrated), not a pre-computed one
    /// nor the hybrid.
    pub fn is_tensor_mass(self) -> bool {
        matches!(
            self,
            Model::TensorMassLinear
                | Model::Stvk
                | Model::StvkPenalty
                | Model::Corotational
                | Model::NeoHookean
        )
    }

    /// A stepped model: tensor-mass, or the hybrid.
    pub fn is_dynamic(self) -> bool {
        self.is_tensor_mass() || self == Model::Hybrid
    }

    /// The law and penalty (N) of the stepped tensor-mass model: the
    /// model's own ([`Model::tensor_mass`]), the hybrid's region's
    /// ([`HYBRID_LAW`]); `None` for the pre-computed models.
    pub fn dynamic_law(self, body: &Body) -> Option<(ElasticLaw, Option<f64>)> {
        match self {
            Model::Hybrid => Some((HYBRID_LAW, None)),
            _ => self.tensor_mass(body),
        }
    }

    /// Name used in the JSON, the charts and the report.
    pub fn name(self) -> &'static str {
        match self {
            Model::PrecomputedLinear => "precomputed-linear",
            Model::PrecomputedQuasi => "precomputed-quasi",
            Model::TensorMassLinear => "tensor-mass-linear",
            Model::Stvk => "stvk",
            Model::StvkPenalty => "stvk-penalty",
            Model::Corotational => "corotational",
            Model::NeoHookean => "neo-hookean",
            Model::Hybrid => "hybrid",
        }
    }
}

/// The hybrid's law on its tensor-mass region.
pub const HYBRID_LAW: ElasticLaw = ElasticLaw::StVenantKirchhoff(StvkForm::PerTet);

/// How many of [`Model::ALL`] are stepped (relaxed to rest, integrated
/// in the trajectories): the tensor-mass models and the hybrid (whose
/// tensor-mass region has at most the mesh's tets).
pub(super) fn relaxed_models() -> usize {
    Model::ALL.iter().filter(|m| m.is_dynamic()).count()
}

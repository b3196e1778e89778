//! Which elastic force the step evaluates (MODELS.md §1 and §4).

/// The constitutive law of the elastic force pass.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ElasticLaw {
    /// Linear elasticity, `f = −K u` from the vertex and edge tensors
    /// (RR-3510 §5, MODELS.md §1). Swells under rotation.
    #[default]
    Linear,
    /// St Venant-Kirchhoff (Picinbono 2001 §3, MODELS.md §4): rotation
    /// invariant, evaluated in the given form (both give the same force to
    /// rounding).
    StVenantKirchhoff(StvkForm),
    /// Co-rotational linear elasticity (stiffness warping, Müller & Gross
    /// 2004; MODELS.md §8), tet by tet: the linear force in each tet's
    /// rotated frame, `f_e = −R K_e (Rᵀ x_e − X_e)`, `R` the closest
    /// rotation to the tet's deformation gradient. Rotation invariant; the
    /// linear law's stiffness at rest.
    Corotational,
    /// Compressible neo-Hookean (Bonet & Wood; MODELS.md §8), tet by tet,
    /// with the volume energy continued quadratically below
    /// [`crate::tensor_mass::NEO_HOOKEAN_J_FLOOR`] so that inverted tets get
    /// a finite restoring force.
    NeoHookean,
}

/// How the St Venant-Kirchhoff force is evaluated.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum StvkForm {
    /// Tet by tet from the deformation gradient, `f_j = −V F S a_j`.
    #[default]
    PerTet,
    /// Picinbono's split (eq. 13–15, table 1): the linear tensors plus
    /// cubic and quartic terms stored on vertices, edges, triangles and
    /// tets, so that a cut is a local subtraction of stored terms.
    Tensors,
}

impl ElasticLaw {
    /// Every law and form, in documentation order.
    pub const ALL: [ElasticLaw; 5] = [
        ElasticLaw::Linear,
        ElasticLaw::StVenantKirchhoff(StvkForm::PerTet),
        ElasticLaw::StVenantKirchhoff(StvkForm::Tensors),
        ElasticLaw::Corotational,
        ElasticLaw::NeoHookean,
    ];
}

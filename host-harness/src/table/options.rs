//! What a table build takes besides the mesh: the table's kind with the
//! options only that kind takes, the material, the fixed predicates and the
//! stored precision ([`BuildOptions`]); read by the build ([`super::build`])
//! and by its size estimate ([`super::estimate`]).

use super::compliance::Solver;
use super::compress::Compression;
use super::precision::Precision;
use crate::fem::material::{Material, TetMaterials};
use crate::fix::FixPredicate;

/// The tool radius (m) a pre-computed table's candidate lists serve unless
/// told otherwise: the default tool's.
pub const DEFAULT_LIST_TOOL_RADIUS_M: f64 = crate::scene::DEFAULT_TOOL_RADIUS_M;

/// Everything a table build needs besides the mesh.
#[derive(Clone, Debug)]
pub struct BuildOptions {
    /// Which table, with the options only that kind takes.
    pub kind: TableKindOptions,
    /// Young's modulus and Poisson ratio of every tet, or the default of
    /// [`Self::tet_materials`] (the table header's).
    pub material: Material,
    /// Per-tet materials (heterogeneous tissue), `None` for every tet of
    /// `material`; set with [`Self::with_tet_materials`].
    pub tet_materials: Option<TetMaterials>,
    /// A vertex matching any predicate is fixed.
    pub fix: Vec<FixPredicate>,
    /// Stored float width.
    pub precision: Precision,
    /// Show a progress bar over the compliance solves (a tensor-mass table
    /// has none).
    pub progress: bool,
}

/// The kind of table to build, and what only that kind needs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TableKindOptions {
    /// The pre-computed compliance table (RR-3510 §4), solved with `solver`
    /// (sparse Cholesky or the paper's CG baseline). Some vertex must match
    /// a predicate (a free body has a singular stiffness) and some must stay
    /// free.
    Precomputed {
        /// How the compliance columns are solved.
        solver: Solver,
        /// Store the compliance compressed ([`super::compress`]; `f32`
        /// tables only), `None` for all of it in the table scalar.
        compression: Option<Compression>,
        /// The largest tool radius (m) the collision index's per-cell
        /// candidate lists serve (a detection by a larger tool walks the
        /// grid instead; `palpate_kernel::table::SurfaceIndex::candidates`).
        tool_radius_m: f64,
    },
    /// The dynamic tensor-mass table (RR-3510 §5). Any predicates, none
    /// included (a free body).
    TensorMass {
        /// Mass density, kg/m³, finite and > 0.
        density_kg_m3: f64,
    },
}

impl BuildOptions {
    /// A pre-computed table of `material` with the `fix` predicates, solved
    /// with `solver`, stored in `precision`, without a progress bar.
    pub fn precomputed(
        material: Material,
        fix: Vec<FixPredicate>,
        solver: Solver,
        precision: Precision,
    ) -> Self {
        Self {
            kind: TableKindOptions::Precomputed {
                solver,
                compression: None,
                tool_radius_m: DEFAULT_LIST_TOOL_RADIUS_M,
            },
            material,
            tet_materials: None,
            fix,
            precision,
            progress: false,
        }
    }

    /// The same options with the compliance stored compressed
    /// (`compression`, [`super::compress`]); nothing changes for a
    /// tensor-mass table or `None`.
    pub fn with_compression(self, compression: Option<Compression>) -> Self {
        match self.kind {
            TableKindOptions::Precomputed {
                solver,
                tool_radius_m,
                ..
            } => Self {
                kind: TableKindOptions::Precomputed {
                    solver,
                    compression,
                    tool_radius_m,
                },
                ..self
            },
            TableKindOptions::TensorMass { .. } => self,
        }
    }

    /// The tool radius a pre-computed table's candidate lists serve, m
    /// ([`DEFAULT_LIST_TOOL_RADIUS_M`] for tensor-mass options).
    pub fn list_tool_radius_m(&self) -> f64 {
        match self.kind {
            TableKindOptions::Precomputed { tool_radius_m, .. } => tool_radius_m,
            TableKindOptions::TensorMass { .. } => DEFAULT_LIST_TOOL_RADIUS_M,
        }
    }

    /// The same options with candidate lists for tools of radius up to
    /// `tool_radius_m` (m); nothing changes for a tensor-mass table.
    pub fn with_tool_radius(self, tool_radius_m: f64) -> Self {
        match self.kind {
            TableKindOptions::Precomputed {
                solver,
                compression,
                ..
            } => Self {
                kind: TableKindOptions::Precomputed {
                    solver,
                    compression,
                    tool_radius_m,
                },
                ..self
            },
            TableKindOptions::TensorMass { .. } => self,
        }
    }

    /// A tensor-mass table of `material` and density `density_kg_m3`
    /// (kg/m³) with the `fix` predicates, stored in `precision`.
    pub fn tensor_mass(
        material: Material,
        density_kg_m3: f64,
        fix: Vec<FixPredicate>,
        precision: Precision,
    ) -> Self {
        Self {
            kind: TableKindOptions::TensorMass { density_kg_m3 },
            material,
            tet_materials: None,
            fix,
            precision,
            progress: false,
        }
    }
}

impl BuildOptions {
    /// The same options with each tet's own material (one per tet of the
    /// mesh the table is built from); [`Self::material`] becomes their
    /// default.
    pub fn with_tet_materials(self, materials: TetMaterials) -> Self {
        Self {
            material: materials.default_material(),
            tet_materials: Some(materials),
            ..self
        }
    }

    /// The material of each of `tet_count` tets: [`Self::tet_materials`], or
    /// [`Self::material`] for every tet. Errors if the per-tet materials are
    /// for another number of tets (another mesh).
    pub fn materials_for(&self, tet_count: usize) -> anyhow::Result<TetMaterials> {
        match &self.tet_materials {
            Some(materials) => {
                materials.check_tet_count(tet_count)?;
                Ok(materials.clone())
            }
            None => Ok(TetMaterials::uniform(self.material, tet_count)),
        }
    }
}

//! One step of the tensor-mass model (RR-3510 §5; Picinbono 2001) timed on
//! a mesh, per elastic law and form, penalty and integrator, and the bytes
//! it reads (for the memory-copy roofline).
//!
//! The state timed: every free vertex displaced by a 20 % shear
//! `u_x = 0.2 (z − z_min)` (so every tet is strained and the St
//! Venant-Kirchhoff terms do real work), at rest, then stepped with
//! `Δt =` [`STEP_DT_S`] and damping [`DAMPING_PER_S`]: the cost of a step
//! does not depend on either, and so short a step keeps the state where it
//! started for the whole measurement. A step that faults (it should not at
//! that step) is counted and the shear restored.

use core::hint::black_box;
use core::mem::size_of;

use anyhow::{Context, bail};
use nalgebra::Vector3;
use palpate_kernel::Real;
use palpate_kernel::math::Dispatch;
use palpate_kernel::table::TensorMassTable;
use palpate_kernel::table::format::{
    EDGE_TERMS_LEN, TET_MATERIAL_LEN, TET_SHAPE_LEN, TET_TERMS_LEN, TRIANGLE_TERMS_LEN,
    VERTEX_TERMS_LEN,
};
use palpate_kernel::tensor_mass::{
    DynamicParams, ElasticLaw, Integrator, StvkForm, TensorMassModel, VertexMode,
};

use super::measure::{Sampling, Timing, time};
use crate::mesh::{MeshReport, TetMesh};
use crate::table::build::{BuildOptions, build};
use crate::table::file::Precision;
use crate::table::load::TableFile;
use crate::tensor_mass::OwnedState;
use crate::tensor_mass::run::diagonal;

/// Time step of the timed steps, s: far below any stable limit of a
/// tissue mesh (the state stays at the shear it starts from).
pub const STEP_DT_S: f64 = 1e-7;

/// Mass-proportional damping of the timed steps, 1/s (any value costs the
/// same).
pub const DAMPING_PER_S: f64 = 5.0;

/// Shear of the timed state: `u_x = SHEAR · (z − z_min)`.
const SHEAR: f64 = 0.2;

/// One configuration of the tensor-mass step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepConfig {
    /// The elastic law and, for St Venant-Kirchhoff, its form.
    pub law: ElasticLaw,
    /// The incompressibility penalty γ (Picinbono 2001 §3.2), N, or `None`.
    pub incompressibility_n: Option<f64>,
    /// The integrator.
    pub integrator: Integrator,
}

impl StepConfig {
    /// The law, form and penalty as `palpate bench --models` names them:
    /// `linear`, `stvk`, `stvk-tensors`, `stvk-incompressible`,
    /// `stvk-tensors-incompressible`, `corotational`, `neo-hookean` (a
    /// linear, co-rotational or neo-Hookean law with the penalty is
    /// `…-incompressible`, which no command measures).
    pub fn model_name(&self) -> &'static str {
        let penalty = self.incompressibility_n.is_some();
        match (self.law, penalty) {
            (ElasticLaw::Linear, false) => "linear",
            (ElasticLaw::Linear, true) => "linear-incompressible",
            (ElasticLaw::StVenantKirchhoff(StvkForm::PerTet), false) => "stvk",
            (ElasticLaw::StVenantKirchhoff(StvkForm::PerTet), true) => "stvk-incompressible",
            (ElasticLaw::StVenantKirchhoff(StvkForm::Tensors), false) => "stvk-tensors",
            (ElasticLaw::StVenantKirchhoff(StvkForm::Tensors), true) => {
                "stvk-tensors-incompressible"
            }
            (ElasticLaw::Corotational, false) => "corotational",
            (ElasticLaw::Corotational, true) => "corotational-incompressible",
            (ElasticLaw::NeoHookean, false) => "neo-hookean",
            (ElasticLaw::NeoHookean, true) => "neo-hookean-incompressible",
        }
    }
}

/// A tensor-mass table's counts, which the bytes of a step follow from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StepCounts {
    /// Vertices `N`.
    pub vertices: u64,
    /// Edges `E` (each once).
    pub edges: u64,
    /// Groups of 4 edges the linear pass reads (the model's edge layout,
    /// `kernel/src/tensor_mass/edges.rs`: about `E / 4`, rows padded).
    pub edge_groups: u64,
    /// Tets `T`.
    pub tets: u64,
    /// Mesh triangles (every face once; the split terms' triangles).
    pub triangles: u64,
}

impl StepCounts {
    /// The counts of a loaded table (the edge groups of a model built on
    /// it).
    pub fn of<T: Real>(table: &TensorMassTable<'_, T>) -> Self {
        let mut state = OwnedState::for_table(table).without_split_terms();
        let params = DynamicParams::linear(T::zero(), T::one());
        let edge_groups = TensorMassModel::new(*table, state.buffers(), params)
            .map_or(0, |model| model.edge_groups().0.last().map_or(0, |&g| g));
        Self {
            vertices: table.vertex_count() as u64,
            edges: table.edge_count() as u64,
            edge_groups: u64::from(edge_groups),
            tets: table.tet_count() as u64,
            triangles: table.mesh_triangles().len() as u64,
        }
    }

    /// The bytes one step of `config` reads with `scalar_bytes`-byte
    /// scalars: each array counted once per pass over it
    /// (`kernel/src/tensor_mass/{force,stvk,stvk_terms,model,integrator}.rs`).
    ///
    /// - linear force pass: vertex tensors (9 scalars each), the edge
    ///   groups (36 scalars and 4 columns of 4 bytes each) and their row
    ///   starts (4 bytes each), `u` and `f` (3 each);
    /// - per-tet pass (St Venant-Kirchhoff, co-rotational, neo-Hookean),
    ///   and the penalty's pass: the tets
    ///   (16 bytes), rest shapes (13 scalars), Lamé pairs (2), alive flags
    ///   (1 byte), `u` and `f`;
    /// - split terms: the linear pass, then the terms' pass over vertices
    ///   (4 scalars), edges (16, and the CSR: 4 bytes per edge and per
    ///   row start), triangles (12 bytes,
    ///   15 scalars), tets (16 bytes, 3 scalars, alive), `u` and `f`;
    /// - the integrator's vertex pass: `u`, `v`, `f`, external forces,
    ///   masses and modes, plus the previous displacements for the central
    ///   difference; RK4 evaluates the forces and the accelerations 4
    ///   times, updates its 4 stage arrays with `u`, `v` and `a` each time,
    ///   copies `u`, `v` and clears 2 arrays first and reads `u`, `v`, the
    ///   2 sums, masses and modes last.
    pub fn step_bytes(&self, config: &StepConfig, scalar_bytes: u64) -> u64 {
        let (n, e, t, tri) = (self.vertices, self.edges, self.tets, self.triangles);
        let groups = self.edge_groups;
        let s = scalar_bytes;
        let vector = 3 * s * n;
        let modes = size_of::<VertexMode>() as u64 * n;
        let csr = 4 * e + 4 * (n + 1);
        let linear = 9 * s * n + (36 * s + 16) * groups + 4 * (n + 1) + 2 * vector;
        let tet_pass = 16 * t + (TET_SHAPE_LEN + TET_MATERIAL_LEN) as u64 * s * t + t + 2 * vector;
        let terms = VERTEX_TERMS_LEN as u64 * s * n
            + EDGE_TERMS_LEN as u64 * s * e
            + csr
            + (12 + TRIANGLE_TERMS_LEN as u64 * s) * tri
            + (16 + TET_TERMS_LEN as u64 * s + 1) * t
            + 2 * vector;
        let law = match config.law {
            ElasticLaw::Linear => linear,
            ElasticLaw::StVenantKirchhoff(StvkForm::PerTet)
            | ElasticLaw::Corotational
            | ElasticLaw::NeoHookean => tet_pass,
            ElasticLaw::StVenantKirchhoff(StvkForm::Tensors) => linear + terms,
        };
        let forces = law
            + if config.incompressibility_n.is_some() {
                tet_pass
            } else {
                0
            };
        // u, v, f, external forces, masses, modes.
        let vertex_pass = 4 * vector + s * n + modes;
        match config.integrator {
            Integrator::ExplicitEuler | Integrator::SymplecticEuler => forces + vertex_pass,
            Integrator::CentralDifference => forces + vertex_pass + vector,
            Integrator::Rk4 => {
                // a (the forces), v, external forces, masses, modes.
                let accelerations = 3 * vector + s * n + modes;
                // su, sv, du, dv, u, v, a.
                let stage = 7 * vector;
                let start = 6 * vector;
                // u, v, du, dv, masses, modes.
                let end = 4 * vector + s * n + modes;
                start + 4 * (forces + accelerations + stage) + end
            }
        }
    }
}

/// The tensor-mass tables of one mesh, built once, timed in any
/// configuration: what `palpate bench` and `palpate chart` time a step with.
pub struct TensorMassBench {
    f32: Option<TableFile>,
    f64: Option<TableFile>,
    /// The shear of the timed state, m, per vertex.
    shear_m: Vec<[f64; 3]>,
    /// Divergence bound: the mesh's bounding-box diagonal, m.
    diagonal_m: f64,
}

/// A timed step: its timing, the bytes it reads ([`StepCounts::step_bytes`])
/// and the faults met while timing (0 in a sound measurement).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepTiming {
    /// Time per step.
    pub timing: Timing,
    /// Bytes one step reads.
    pub bytes: u64,
    /// Steps that faulted (each followed by the shear restored, untimed
    /// work inside the timing).
    pub faults: u64,
    /// The table's counts.
    pub counts: StepCounts,
}

impl TensorMassBench {
    /// Builds the tensor-mass tables of `mesh` that `options` describe (a
    /// tensor-mass kind: material, density, fixed vertices) in each of
    /// `precisions`.
    pub fn new(
        mesh: &TetMesh,
        report: &MeshReport,
        options: &BuildOptions,
        precisions: &[Precision],
    ) -> anyhow::Result<Self> {
        let table = |precision: Precision| -> anyhow::Result<Option<TableFile>> {
            if !precisions.contains(&precision) {
                return Ok(None);
            }
            let options = BuildOptions {
                precision,
                progress: false,
                ..options.clone()
            };
            let built = build(mesh, report, &options)?;
            Ok(Some(TableFile::from_bytes(&built.bytes)))
        };
        let z_min = mesh
            .positions
            .iter()
            .map(|p| p[2])
            .fold(f64::INFINITY, f64::min);
        Ok(Self {
            f32: table(Precision::F32)?,
            f64: table(Precision::F64)?,
            shear_m: mesh
                .positions
                .iter()
                .map(|p| [SHEAR * (p[2] - z_min), 0.0, 0.0])
                .collect(),
            diagonal_m: diagonal(&mesh.positions),
        })
    }

    /// Times one step of `config` in `precision` with its passes run
    /// through `dispatch`, as `sampling` says.
    pub fn time_step(
        &self,
        config: &StepConfig,
        precision: Precision,
        dispatch: impl Dispatch,
        sampling: &Sampling,
    ) -> anyhow::Result<StepTiming> {
        let (file, bytes) = match precision {
            Precision::F32 => (&self.f32, 4),
            Precision::F64 => (&self.f64, 8),
        };
        let Some(file) = file else {
            bail!("no {precision:?} table was built for this bench");
        };
        match precision {
            Precision::F32 => self.time_in::<f32>(file, config, dispatch, sampling, bytes),
            Precision::F64 => self.time_in::<f64>(file, config, dispatch, sampling, bytes),
        }
    }

    fn time_in<T: Real>(
        &self,
        file: &TableFile,
        config: &StepConfig,
        dispatch: impl Dispatch,
        sampling: &Sampling,
        scalar_bytes: u64,
    ) -> anyhow::Result<StepTiming> {
        let table = TensorMassTable::<T>::load(file.bytes()).context("tensor-mass table")?;
        let counts = StepCounts::of(&table);
        let mut state = OwnedState::for_table(&table);
        let params = DynamicParams::linear(T::of_f64(DAMPING_PER_S), T::of_f64(self.diagonal_m))
            .with_law(config.law)
            .with_incompressibility(config.incompressibility_n.map(T::of_f64));
        let mut model = TensorMassModel::new(table, state.buffers(), params)?;
        let shear = |model: &mut TensorMassModel<'_, '_, T>| {
            model.reset();
            for (v, d) in self.shear_m.iter().enumerate() {
                let d = Vector3::from(d.map(T::of_f64));
                // Fixed vertices refuse; the others take the shear, at rest.
                if model.impose(v as u32, d).is_ok() {
                    let _ = model.release(v as u32);
                }
            }
        };
        shear(&mut model);
        let dt = T::of_f64(STEP_DT_S);
        let mut faults = 0;
        let timing = time(sampling, || {
            let stepped = model.step_with(dispatch, black_box(config.integrator), dt);
            if black_box(stepped).is_err() {
                faults += 1;
                shear(&mut model);
            }
        });
        Ok(StepTiming {
            timing,
            bytes: counts.step_bytes(config, scalar_bytes),
            faults,
            counts,
        })
    }
}

/// Times one step of `config` on `mesh` (its tensor-mass table built from
/// `options` in `precision`) with `dispatch`, as `sampling` says: the one
/// call `palpate chart` needs for a configuration's cost.
pub fn time_step_on_mesh(
    mesh: &TetMesh,
    report: &MeshReport,
    options: &BuildOptions,
    config: &StepConfig,
    precision: Precision,
    dispatch: impl Dispatch,
    sampling: &Sampling,
) -> anyhow::Result<StepTiming> {
    TensorMassBench::new(mesh, report, options, &[precision])?
        .time_step(config, precision, dispatch, sampling)
}

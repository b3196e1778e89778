//! What a session's loop is built from: the loop configuration of a scene ([`loop_config`]),
//! a dynamic scene's table and settings ([`DynamicSetup`]), and what a session reads of a
//! tissue stepped at the physics rate ([`PhysicsView`]).

use anyhow::Context;
use palpate_kernel::haptic::{DynamicLoop, LoopConfig, SafetyLimits};
use palpate_kernel::math::Dispatch;
use palpate_kernel::table::TensorMassTable;
use palpate_kernel::tensor_mass::{
    DynamicParams, DynamicTissue, ElasticLaw, PhysicsConfig, StvkForm, SurfaceBuffers,
    TearThresholds, Tearing, TensorMassModel,
};

use crate::scene::{DynamicSpec, Scene};
use crate::tensor_mass::run::diagonal;
use crate::tensor_mass::{OwnedState, OwnedSurface};
use crate::threads::split_model;

/// The haptic loop configuration of `scene` (f32).
pub fn loop_config(scene: &Scene) -> LoopConfig<f32> {
    LoopConfig {
        radius_m: scene.tool.radius_m as f32,
        dt_s: scene.tick_s() as f32,
        limits: SafetyLimits {
            max_force_n: scene.safety.max_force_n as f32,
            max_slew_n_per_s: scene.safety.max_slew_n_per_s as f32,
        },
    }
}

/// A dynamic scene's table and settings: everything to build its loop.
pub struct DynamicSetup<'t> {
    table: TensorMassTable<'t, f32>,
    params: DynamicParams<f32>,
    physics: PhysicsConfig<f32>,
    config: LoopConfig<f32>,
}

impl<'t> DynamicSetup<'t> {
    /// The settings of dynamic `scene` (model `spec`) over `table`: its law,
    /// penalty and damping, no gravity (the tissue rests in its meshed
    /// shape), divergence when a displacement exceeds the mesh's
    /// bounding-box diagonal; the physics period in steps of `dt_s`; the
    /// scene's cut capacity and tearing.
    pub fn of(
        scene: &Scene,
        spec: &DynamicSpec,
        table: TensorMassTable<'t, f32>,
    ) -> anyhow::Result<Self> {
        let rest: Vec<[f64; 3]> = table
            .rest_positions()
            .iter()
            .map(|p| p.map(f64::from))
            .collect();
        Ok(Self {
            table,
            params: DynamicParams::linear(spec.damping_per_s as f32, diagonal(&rest) as f32)
                .with_law(spec.law)
                .with_incompressibility(spec.incompressibility_n.map(|g| g as f32)),
            physics: PhysicsConfig {
                extrapolation: spec.extrapolation,
                integrator: spec.integrator,
                dt_s: spec.dt_s as f32,
                substeps: scene
                    .dynamic_substeps()
                    .context("physics period is not a whole number of dt_s")?,
                cut_capacity_tets: scene.cutting.capacity_tets,
                cut_force_n: scene.cutting.force_n as f32,
                tearing: scene.tearing.map(|t| Tearing {
                    thresholds: TearThresholds {
                        volume_change: t.volume_change.map(|x| x as f32),
                        mean_elongation: t.mean_elongation.map(|x| x as f32),
                        max_elongation: t.max_elongation.map(|x| x as f32),
                    },
                    capacity_tets: t.capacity_tets,
                }),
            },
            config: loop_config(scene),
        })
    }

    /// Builds the model, its surface and the loop at rest on heap buffers
    /// and runs `body` on the loop, the model's steps through `dispatch`
    /// (`session run`: [`crate::dispatch::HostDispatch::detect`]; `budget`:
    /// portable).
    pub fn with_loop<const P: usize, R, D: Dispatch>(
        &self,
        dispatch: D,
        body: impl FnOnce(&mut DynamicLoop<'_, '_, f32, P, P, D>) -> anyhow::Result<R>,
    ) -> anyhow::Result<R> {
        self.with_parts(dispatch.parts(), |model, buffers, forces| {
            let tissue = DynamicTissue::<f32, P>::new(model, buffers, forces, self.physics)
                .map_err(|e| anyhow::anyhow!("dynamic tissue: {e}"))?
                .with_dispatch(dispatch);
            let mut haptic = DynamicLoop::<f32, P, P, D>::new(tissue, self.config)
                .map_err(|e| anyhow::anyhow!("haptic loop: {e}"))?;
            body(&mut haptic)
        })
    }

    /// Builds the model at rest and its surface buffers and force scratch
    /// on the heap (the split-term buffers only for the form that reads
    /// them; the split per-tet pass's for `threads > 1`,
    /// [`crate::threads::split_model`]), and runs `body` on them: what a
    /// dynamic or hybrid tissue is built from.
    pub fn with_parts<R>(
        &self,
        threads: usize,
        body: impl FnOnce(
            TensorMassModel<'_, '_, f32>,
            SurfaceBuffers<'_, f32>,
            &mut [[f32; 3]],
        ) -> anyhow::Result<R>,
    ) -> anyhow::Result<R> {
        let state = OwnedState::for_table(&self.table);
        let mut state = if self.params.law == ElasticLaw::StVenantKirchhoff(StvkForm::Tensors) {
            state
        } else {
            state.without_split_terms()
        };
        let mut split = None;
        let model = TensorMassModel::new(self.table, state.buffers(), self.params)
            .and_then(|model| split_model(model, &mut split, threads))
            .map_err(|e| anyhow::anyhow!("dynamic model: {e}"))?;
        let mut surface = OwnedSurface::for_model(&model);
        let (buffers, forces) = surface.buffers();
        body(model, buffers, forces)
    }

    /// The tensor-mass table.
    pub fn table(&self) -> TensorMassTable<'t, f32> {
        self.table
    }

    /// The tensor-mass model's parameters.
    pub fn params(&self) -> DynamicParams<f32> {
        self.params
    }

    /// The physics settings.
    pub fn physics(&self) -> PhysicsConfig<f32> {
        self.physics
    }

    /// The haptic loop settings.
    pub fn config(&self) -> LoopConfig<f32> {
        self.config
    }
}

/// What a session reads of a tissue stepped at the physics rate, in the
/// mesh's numbering.
pub trait PhysicsView<B> {
    /// The mesh tets the last physics update removed, in removal order.
    fn removed(&self, tissue: &B) -> Vec<u32>;
    /// The displacement of every mesh vertex (m) and which tets live.
    fn frame(&self, tissue: &B) -> anyhow::Result<(Vec<[f32; 3]>, Vec<bool>)>;
}

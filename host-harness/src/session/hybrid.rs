//! A session on the hybrid model (RR-3510 §6.2): the tensor-mass region's
//! setup of a dynamic scene, the pre-computed region's and interface
//! tables, and the map from the region's tets back to the mesh's.

use anyhow::Context;
use palpate_kernel::PrecomputedTable;
use palpate_kernel::haptic::HybridLoop;
use palpate_kernel::hybrid::HybridTissue;
use palpate_kernel::math::Dispatch;
use palpate_kernel::table::{InterfaceTable, TensorMassTable};

use super::model::HybridFiles;
use super::setup::{DynamicSetup, PhysicsView};
use crate::hybrid::owned::OwnedHybridBuffers;
use crate::scene::{DynamicSpec, Scene};

/// A hybrid scene's tables and settings: everything to build its loop.
pub struct HybridSetup<'t> {
    dynamic: DynamicSetup<'t>,
    precomputed: PrecomputedTable<'t, f32>,
    interface: InterfaceTable<'t, f32>,
    /// The mesh tet of each tet of the tensor-mass region.
    mesh_tet: Vec<u32>,
    /// Tets of the mesh.
    tet_count: usize,
}

impl<'t> HybridSetup<'t> {
    /// The settings of `scene` (its tensor-mass region's `spec`) over the f32
    /// `tables`.
    pub fn of(scene: &Scene, spec: &DynamicSpec, tables: &'t HybridFiles) -> anyhow::Result<Self> {
        let dynamic = TensorMassTable::<f32>::load(tables.dynamic.bytes())
            .context("tensor-mass region table")?;
        Ok(Self {
            dynamic: DynamicSetup::of(scene, spec, dynamic)?,
            precomputed: PrecomputedTable::<f32>::load(tables.precomputed.bytes())
                .context("pre-computed region table")?,
            interface: InterfaceTable::<f32>::load(tables.interface.bytes())
                .context("interface table")?,
            mesh_tet: mesh_tets(&tables.dynamic_tet),
            tet_count: tables.dynamic_tet.len(),
        })
    }

    /// The tensor-mass region's setup.
    pub fn dynamic(&self) -> &DynamicSetup<'t> {
        &self.dynamic
    }

    /// What the session reads of the tissue, in mesh numbering.
    pub fn view(&self) -> HybridView<'_> {
        HybridView {
            mesh_tet: &self.mesh_tet,
            tet_count: self.tet_count,
        }
    }

    /// Builds the tissue and the loop at rest on heap buffers and runs
    /// `body` on the loop, the tensor-mass region's steps through
    /// `dispatch` (its per-tet pass split into `dispatch.parts()`).
    pub fn with_loop<const P: usize, R, D: Dispatch>(
        &self,
        dispatch: D,
        body: impl FnOnce(&mut HybridLoop<'_, '_, f32, P, P, D>) -> anyhow::Result<R>,
    ) -> anyhow::Result<R> {
        self.with_tissue::<P, _, _>(dispatch, |tissue| {
            let mut haptic = HybridLoop::<f32, P, P, D>::new(tissue, self.dynamic.config())
                .map_err(|e| anyhow::anyhow!("haptic loop: {e}"))?;
            body(&mut haptic)
        })
    }

    /// Builds the tissue at rest on heap buffers, its tensor-mass region's
    /// steps through `dispatch`, and runs `body` on it.
    pub fn with_tissue<const P: usize, R, D: Dispatch>(
        &self,
        dispatch: D,
        body: impl FnOnce(HybridTissue<'_, '_, f32, P, P, D>) -> anyhow::Result<R>,
    ) -> anyhow::Result<R> {
        let table = self.dynamic.table();
        let mut owned = OwnedHybridBuffers::for_tables(&self.precomputed, &table, &self.interface);
        self.dynamic
            .with_parts(dispatch.parts(), |model, buffers, forces| {
                let (coupling, surface) = owned.buffers();
                let tissue = HybridTissue::<f32, P, P>::new(
                    model,
                    buffers,
                    forces,
                    self.dynamic.physics(),
                    self.precomputed,
                    self.interface,
                    coupling,
                    surface,
                )
                .map_err(|e| anyhow::anyhow!("hybrid tissue: {e}"))?;
                body(tissue.with_dispatch(dispatch))
            })
    }
}

/// The mesh tet of each tet of the tensor-mass region (its tets are the
/// mesh's dynamic ones, `dynamic_tet`, in mesh order).
fn mesh_tets(dynamic_tet: &[bool]) -> Vec<u32> {
    (0..dynamic_tet.len() as u32)
        .filter(|&t| dynamic_tet[t as usize])
        .collect()
}

/// A hybrid session's view of its tissue in mesh numbering.
pub struct HybridView<'v> {
    mesh_tet: &'v [u32],
    tet_count: usize,
}

impl<const P: usize, D: Dispatch> PhysicsView<HybridTissue<'_, '_, f32, P, P, D>>
    for HybridView<'_>
{
    fn removed(&self, tissue: &HybridTissue<'_, '_, f32, P, P, D>) -> Vec<u32> {
        let removed = tissue.dynamic().removed().iter();
        removed
            .filter_map(|&t| self.mesh_tet.get(t as usize).copied())
            .collect()
    }

    fn frame(
        &self,
        tissue: &HybridTissue<'_, '_, f32, P, P, D>,
    ) -> anyhow::Result<(Vec<[f32; 3]>, Vec<bool>)> {
        let model = tissue.dynamic().model();
        let mut u = vec![[0.0f32; 3]; tissue.region().interface().vertex_count()];
        // A faulted region's field is not read: the frame shows rest.
        let _ = tissue
            .region()
            .displacements(model, tissue.solution(), &mut u);
        let mut alive = vec![true; self.tet_count];
        for (&t, &a) in self.mesh_tet.iter().zip(model.tet_alive()) {
            alive[t as usize] = a;
        }
        Ok((u, alive))
    }
}

//! The hybrid tissue (RR-3510 §6.2): the three tables in flash, the
//! tensor-mass region's state and surface, the coupling and the whole
//! surface in the arena (the host's lengths:
//! `palpate::hybrid::owned::OwnedHybridBuffers::for_tables`), a `HybridLoop`
//! per run; the tick between physics updates is measured.

use core::fmt::Write;
use palpate_kernel::table::format::PLANE_LEN;

use cortex_m_semihosting::hio::HostStream;
use palpate_kernel::haptic::HybridLoop;
use palpate_kernel::hybrid::{HybridBuffers, HybridSurfaceBuffers, HybridTissue};
use palpate_kernel::table::{InterfaceTable, TensorMassTable};
use palpate_kernel::{PrecomputedTable, include_table};
use palpate_script::ticks::Recording;

use crate::arena::Arena;
use crate::buffers::model_parts;
use crate::{Failed, Measured, Ticking, refuse};

/// The pre-computed region's table, 16-byte aligned in flash.
static PRECOMPUTED: &[u8] = include_table!(concat!(env!("OUT_DIR"), "/precomputed.bin"));
/// The tensor-mass region's table.
static DYNAMIC: &[u8] = include_table!(concat!(env!("OUT_DIR"), "/dynamic.bin"));
/// The interface table.
static INTERFACE: &[u8] = include_table!(concat!(env!("OUT_DIR"), "/interface.bin"));

/// The loaded tables.
pub struct Model {
    precomputed: PrecomputedTable<'static, f32>,
    dynamic: TensorMassTable<'static, f32>,
    interface: InterfaceTable<'static, f32>,
}

impl Model {
    /// Loads the tables and reports them on a `#` line.
    pub fn load(out: &mut HostStream) -> Result<Self, Failed> {
        let (precomputed, dynamic, interface) = match (
            PrecomputedTable::<f32>::load(PRECOMPUTED),
            TensorMassTable::<f32>::load(DYNAMIC),
            InterfaceTable::<f32>::load(INTERFACE),
        ) {
            (Ok(p), Ok(d), Ok(i)) => (p, d, i),
            (p, d, i) => {
                let _ = writeln!(
                    out,
                    "# tables refused: {:?} {:?} {:?}",
                    p.err(),
                    d.err(),
                    i.err()
                );
                return Err(());
            }
        };
        let _ = writeln!(
            out,
            "# hybrid tables: {} + {} + {} bytes in flash (pre-computed, tensor-mass, \
             interface); {} vertices, {} tensor-mass, {} connection nodes",
            PRECOMPUTED.len(),
            DYNAMIC.len(),
            INTERFACE.len(),
            precomputed.vertex_count(),
            dynamic.vertex_count(),
            interface.connection_count()
        );
        Ok(Self {
            precomputed,
            dynamic,
            interface,
        })
    }
}

impl Model {
    /// The coupling's and the whole surface's buffers.
    fn buffers<'a>(
        &self,
        arena: &'a Arena,
    ) -> Result<(HybridBuffers<'a, f32>, HybridSurfaceBuffers<'a, f32>), &'static str> {
        let full = "arena full";
        let l = HybridSurfaceBuffers::<f32>::lengths(
            &self.precomputed,
            &self.dynamic,
            self.precomputed.vertex_count(),
        );
        let zero = [0.0f32; 3];
        let coupling = HybridBuffers {
            passed_force_n: arena
                .slice(self.interface.connection_count(), zero)
                .ok_or(full)?,
            background_m: arena.slice(self.interface.free_count(), zero).ok_or(full)?,
        };
        let buffers = HybridSurfaceBuffers {
            positions_m: arena.slice(l.vertices, zero).ok_or(full)?,
            triangles: arena.slice(l.triangles, [0; 3]).ok_or(full)?,
            planes: arena.slice(l.triangles, [0.0; PLANE_LEN]).ok_or(full)?,
            vertex_triangle_start: arena.slice(l.vertices + 1, 0).ok_or(full)?,
            vertex_triangle: arena.slice(3 * l.triangles, 0).ok_or(full)?,
            cell_start: arena.slice(l.cell_start, 0).ok_or(full)?,
            grid_vertex: arena.slice(l.vertices, 0).ok_or(full)?,
            mesh_vertex: arena.slice(l.dynamic_vertices, 0).ok_or(full)?,
        };
        Ok((coupling, buffers))
    }
}

impl Measured for Model {
    fn with_loop<const P: usize>(
        &self,
        recording: &Recording<'_>,
        arena: &Arena,
        out: &mut HostStream,
        body: impl FnOnce(&mut dyn Ticking<P>, &mut HostStream) -> Result<(), Failed>,
    ) -> Result<(), Failed> {
        let settings = recording.header().settings;
        let Some((params, physics)) = settings.dynamic else {
            refuse(out, "the recording has no dynamic settings");
            return Err(());
        };
        let (model, surface, forces) =
            model_parts(arena, self.dynamic, params).map_err(|e| refuse(out, e))?;
        let (coupling, buffers) = self.buffers(arena).map_err(|e| refuse(out, e))?;
        let tissue = HybridTissue::<f32, P, P>::new(
            model,
            surface,
            forces,
            physics,
            self.precomputed,
            self.interface,
            coupling,
            buffers,
        )
        .map_err(|e| refuse(out, e))?;
        let mut haptic = HybridLoop::<f32, P, P>::new(tissue, settings.loop_config)
            .map_err(|e| refuse(out, e))?;
        let _ = writeln!(out, "# arena: {} bytes", arena.used());
        body(&mut haptic, out)
    }
}

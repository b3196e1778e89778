//! The dynamic tissue (RR-3510 §5, the tensor-mass model): its table in
//! flash, its state and surface in the arena, a `DynamicLoop` per run with
//! the recorded parameters and physics; the tick between physics updates is
//! measured, the updates run outside it.

use core::fmt::Write;

use cortex_m_semihosting::hio::HostStream;
use palpate_kernel::haptic::DynamicLoop;
use palpate_kernel::include_table;
use palpate_kernel::table::TensorMassTable;
use palpate_kernel::tensor_mass::DynamicTissue;
use palpate_script::ticks::Recording;

use crate::arena::Arena;
use crate::buffers::model_parts;
use crate::{Failed, Measured, Ticking, refuse};

/// The f32 tensor-mass table of the recorded scene, 16-byte aligned.
static TABLE: &[u8] = include_table!(concat!(env!("OUT_DIR"), "/table.bin"));

/// The loaded table.
pub struct Model {
    table: TensorMassTable<'static, f32>,
}

impl Model {
    /// Loads the table and reports it on a `#` line.
    pub fn load(out: &mut HostStream) -> Result<Self, Failed> {
        let table = TensorMassTable::<f32>::load(TABLE).map_err(|e| {
            let _ = writeln!(out, "# table refused: {e}");
        })?;
        let _ = writeln!(
            out,
            "# tensor-mass table: {} bytes in flash, {} vertices, {} tets",
            TABLE.len(),
            table.vertex_count(),
            table.tet_count()
        );
        Ok(Self { table })
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
            model_parts(arena, self.table, params).map_err(|e| refuse(out, e))?;
        let tissue = DynamicTissue::<f32, P>::new(model, surface, forces, physics)
            .map_err(|e| refuse(out, e))?;
        let mut haptic = DynamicLoop::<f32, P, P>::new(tissue, settings.loop_config)
            .map_err(|e| refuse(out, e))?;
        let _ = writeln!(out, "# arena: {} bytes", arena.used());
        body(&mut haptic, out)
    }
}

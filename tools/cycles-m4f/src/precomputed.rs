//! The pre-computed tissue (RR-3510 §4): its table in flash, a
//! `PrecomputedLoop` per run, no physics update (the contact solve runs in
//! every tick; the deformation field is not part of the tick).

use core::fmt::Write;

use cortex_m_semihosting::hio::HostStream;
use palpate_kernel::haptic::{ForceOutput, PrecomputedLoop, TickCounters, ToolInput};
use palpate_kernel::precomputed::PrecomputedTissue;
use palpate_kernel::{PrecomputedTable, include_table};
use palpate_script::ticks::Recording;

use crate::arena::Arena;
use crate::{Failed, Measured, Ticking, measured_tick, refuse};

/// The f32 table of the recorded scene, 16-byte aligned in flash.
static TABLE: &[u8] = include_table!(concat!(env!("OUT_DIR"), "/table.bin"));

/// The loaded table.
pub struct Model {
    table: PrecomputedTable<'static, f32>,
}

impl Model {
    /// Loads the table and reports it on a `#` line.
    pub fn load(out: &mut HostStream) -> Result<Self, Failed> {
        let table = PrecomputedTable::<f32>::load(TABLE)
            .map_err(|e| refuse(out, format_args!("table refused: {e}")))?;
        let _ = writeln!(
            out,
            "# pre-computed table: {} bytes in flash, {} vertices, {} touchable",
            TABLE.len(),
            table.vertex_count(),
            table.touchable_count()
        );
        Ok(Self { table })
    }
}

impl Measured for Model {
    fn with_loop<const P: usize>(
        &self,
        recording: &Recording<'_>,
        _arena: &Arena,
        out: &mut HostStream,
        body: impl FnOnce(&mut dyn Ticking<P>, &mut HostStream) -> Result<(), Failed>,
    ) -> Result<(), Failed> {
        let config = recording.header().settings.loop_config;
        let haptic = PrecomputedLoop::<f32, P, P>::new(PrecomputedTissue::new(&self.table), config)
            .map_err(|e| refuse(out, format_args!("haptic loop: {e}")))?;
        body(&mut Quasistatic(haptic), out)
    }
}

/// The pre-computed loop: nothing to update between ticks.
struct Quasistatic<'a, const P: usize>(PrecomputedLoop<'a, f32, P, P>);

impl<const P: usize> Ticking<P> for Quasistatic<'_, P> {
    fn tick(&mut self, tools: &[ToolInput<f32>; P]) -> ForceOutput<f32> {
        measured_tick(&mut self.0, tools)
    }

    fn counters(&self) -> TickCounters {
        *self.0.counters()
    }

    fn physics_update(&mut self) {}
}

//! The sizes of a hybrid model's three tables and its build's peak memory, estimated from the
//! split's counts before any array is computed, and checked against the limits every table
//! build applies (`table::estimate`). [`build_hybrid`](super::build_hybrid) checks it before
//! it builds anything, and `scene plan` reports the same figures
//! (`partition::cost`): one estimate for both.
//!
//! - The pre-computed region's table: [`TableEstimate::of_surface`] of the region's mesh (mesh
//!   numbering, the vertices outside it and the connection nodes fixed), as the builder builds
//!   it: quadratic in its touchable vertices.
//! - The tensor-mass region's table: linear in its mesh.
//! - The interface: the `3c × 3c` condensed stiffness `S` and the `3F_P × 3c` response `H`
//!   (`c` connection nodes, `F_P` free pre-computed vertices), and the dense right-hand sides of
//!   the condensation (`24·F_P·(3c + 1)` bytes, twice: the solve's and `H`'s copy).
//! - Compressed (`[tables] compress = "hmatrix"`, [`HybridEstimate::compressed`]): the
//!   hierarchical `S` (`super::hmatrix::estimate`, every far block at the pre-computed
//!   tables' estimate rank) in place of the dense one, and with a hierarchical region its
//!   table's own estimate (`TableEstimate`'s for `--compress hmatrix`) and the response over
//!   the `S_P` touchable rows only (`3S_P × 3c`).
//! - The peak: the pre-computed build's, or after it the pre-computed table held while the
//!   interface is condensed and the tensor-mass table is written, whichever is larger.

use palpate_kernel::table::format::TableKind;

use super::hmatrix::InterfaceCompression;
use super::split::RegionSplit;
use crate::limits::human_bytes;
use crate::mesh::{MeshReport, Surface, TetMesh, boundary_surface};
use crate::table::estimate::{SizeLimits, TableCounts, TableEstimate, instead};
use crate::table::file::Precision;

/// The estimate of a hybrid's three tables.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct HybridEstimate {
    /// The pre-computed region's table.
    pub precomputed: TableEstimate,
    /// The tensor-mass region's table.
    pub dynamic: TableEstimate,
    /// The interface table.
    pub interface: TableEstimate,
    /// The whole build's peak working memory, bytes (module doc), saturating.
    pub peak_bytes: u64,
    /// Multiply-adds of one product `S u` over the connection nodes (the interface update):
    /// `9c²` dense, one per stored scalar hierarchical (estimated).
    pub condensed_scalars: u64,
}

/// The pre-computed region's build inputs, as [`build_hybrid`](super::build_hybrid) takes them:
/// its mesh (mesh numbering), its fixed flags (the scene's, the vertices outside it and the
/// connection nodes) and its boundary surface.
pub struct PrecomputedRegion {
    /// The region's tets over the whole mesh's vertices.
    pub mesh: TetMesh,
    /// Per mesh vertex: fixed in the region's table.
    pub fixed: Vec<bool>,
    /// The region's boundary surface.
    pub surface: Surface,
}

impl PrecomputedRegion {
    /// The pre-computed region of `split` on `mesh`, the scene fixing `fixed`.
    pub fn of(mesh: &TetMesh, split: &RegionSplit, fixed: &[bool]) -> Self {
        let pmesh = split.precomputed_mesh(mesh);
        let mut pfixed = fixed.to_vec();
        for (v, f) in pfixed.iter_mut().enumerate() {
            *f |= !split.in_precomputed[v] || split.dynamic_index[v].is_some();
        }
        let surface = boundary_surface(&pmesh);
        Self {
            mesh: pmesh,
            fixed: pfixed,
            surface,
        }
    }
}

impl HybridEstimate {
    /// The estimate of the hybrid of `split` on `mesh` (`fixed`: the scene's fixed vertices),
    /// its pre-computed region `region` ([`PrecomputedRegion::of`]), the pre-computed table's
    /// candidate lists for tools up to `tool_radius_m`, stored in `precision`.
    pub fn of(
        mesh: &TetMesh,
        split: &RegionSplit,
        fixed: &[bool],
        region: &PrecomputedRegion,
        tool_radius_m: f64,
        precision: Precision,
    ) -> Self {
        let none = MeshReport::default();
        let precomputed = TableEstimate::of_surface(
            TableKind::Precomputed,
            precision,
            &region.mesh,
            &region.fixed,
            &region.surface,
            tool_radius_m,
        );
        let dmesh = split.dynamic_mesh(mesh);
        let dfixed: Vec<bool> = split
            .dynamic_vertex
            .iter()
            .map(|&v| fixed[v as usize])
            .collect();
        let dsurface = boundary_surface(&dmesh);
        let dynamic = TableEstimate::new(
            TableKind::TensorMass,
            precision,
            TableCounts::of(&dmesh, &none, &dfixed, &dsurface),
        );
        let interface = TableEstimate::new(
            TableKind::Interface,
            precision,
            TableCounts {
                vertices: mesh.positions.len() as u64,
                tets: mesh.tets.len() as u64,
                free: precomputed.counts.free,
                touchable: precomputed.counts.touchable,
                connections: split.connection.len() as u64,
                ..TableCounts::default()
            },
        );
        let c = split.connection.len() as u64;
        Self {
            precomputed,
            dynamic,
            interface,
            peak_bytes: 0,
            condensed_scalars: c.saturating_mul(c).saturating_mul(9),
        }
        .with_peak()
    }

    /// The same with the peak (module doc) of its tables.
    fn with_peak(self) -> Self {
        let after = self
            .precomputed
            .table_bytes
            .saturating_add(self.interface.peak_bytes)
            .saturating_add(self.dynamic.peak_bytes);
        Self {
            peak_bytes: self.precomputed.peak_bytes.max(after),
            ..self
        }
    }

    /// The estimate of the same hybrid compressed (module doc): the interface's `S`
    /// hierarchical as `compression` asks, and with `region` (the pre-computed region,
    /// [`HybridOptions::compress_region`](super::HybridOptions::compress_region)) its table
    /// hierarchical and the interface's response over its touchable rows only.
    pub fn compressed(
        self,
        mesh: &TetMesh,
        split: &RegionSplit,
        precomputed: &PrecomputedRegion,
        compression: &InterfaceCompression,
        region: bool,
    ) -> Self {
        let scalar = u64::from(self.interface.precision.scalar_bytes());
        let points: Vec<[f64; 3]> = split
            .connection
            .iter()
            .map(|&v| mesh.positions[v as usize])
            .collect();
        let c = points.len() as u64;
        let dense = 9 * c * c;
        let (scalars, bytes) = super::hmatrix::estimate(&points, compression, scalar);
        let mut interface = self.interface;
        (interface.compressed, interface.hierarchical) = (true, true);
        interface.table_bytes = interface
            .table_bytes
            .saturating_add(bytes)
            .saturating_sub(dense * scalar);
        let mut table = self.precomputed;
        if region {
            let counts = &self.interface.counts;
            let interior = counts.free.saturating_sub(counts.touchable);
            interface.table_bytes = interface
                .table_bytes
                .saturating_sub(interior.saturating_mul(9 * c * scalar));
            table = table.hierarchical(
                &precomputed.mesh,
                &precomputed.fixed,
                &precomputed.surface,
                false,
            );
        }
        Self {
            precomputed: table,
            interface,
            condensed_scalars: scalars,
            ..self
        }
        .with_peak()
    }

    /// The three tables, in the order they are built.
    pub fn tables(&self) -> [&TableEstimate; 3] {
        [&self.precomputed, &self.dynamic, &self.interface]
    }

    /// One line for people: the three tables' sizes and the peak.
    pub fn describe(&self) -> String {
        format!(
            "the hybrid's tables: pre-computed region {}, tensor-mass region {}, interface {} \
             ({} connection nodes x {} free pre-computed vertices); the build needs about {} of \
             memory",
            human_bytes(self.precomputed.table_bytes),
            human_bytes(self.dynamic.table_bytes),
            human_bytes(self.interface.table_bytes),
            self.interface.counts.connections,
            self.interface.counts.free,
            human_bytes(self.peak_bytes)
        )
    }

    /// Why the build is refused by `limits` (a table above the sizes, or the peak above the
    /// memory available), one line naming the table, or `None` when it fits.
    pub fn refusal(&self, limits: &SizeLimits) -> Option<String> {
        let sizes = SizeLimits {
            available_bytes: None,
            ..*limits
        };
        for (name, table) in ["pre-computed region", "tensor-mass region", "interface"]
            .into_iter()
            .zip(self.tables())
        {
            if let Some(reason) = sizes.refusal(table) {
                return Some(format!(
                    "{reason} ({name}: {}); {}",
                    table.describe(),
                    instead(table.kind)
                ));
            }
        }
        limits
            .available_bytes
            .filter(|&available| self.peak_bytes > available)
            .map(|available| {
                format!(
                    "only {} of memory is available (MemAvailable); {HYBRID_INSTEAD}",
                    human_bytes(available)
                )
            })
    }

    /// Refuses the build above `limits` ([`Self::refusal`]) with one line starting with
    /// `source`: the estimate, the limit and what to do instead; otherwise prints the estimate
    /// on stderr if `limits` asks.
    pub fn check(&self, limits: &SizeLimits, source: &str) -> anyhow::Result<()> {
        let prefix = if source.is_empty() {
            String::new()
        } else {
            format!("{source}: ")
        };
        if let Some(reason) = self.refusal(limits) {
            anyhow::bail!(
                "{prefix}{}; refused before building: {reason}",
                self.describe()
            );
        }
        if limits.print_estimate {
            crate::output::stderr::line(&format!("{prefix}estimate: {}", self.describe()));
        }
        Ok(())
    }
}

/// What to do about a hybrid whose build needs more memory than there is.
pub const HYBRID_INSTEAD: &str = "make the dynamic zones smaller (fewer connection nodes), use \
     a coarser mesh, or fix more of the surface (fewer touchable pre-computed vertices)";

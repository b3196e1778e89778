//! A table's size and its build's peak memory, estimated from the mesh's counts before any
//! array is computed (nothing unbounded), and the limits a build checks them against.
//!
//! A pre-computed table stores `B = S(S+1)/2 + (F−S)·S` compliance blocks of 3×3 scalars
//! (`F` free, `S` touchable vertices; `kernel/src/table/format/mod.rs`): quadratic in the mesh. A
//! 40³-cell box with its base fixed (68 921 vertices, 7 921 touchable) has 5.0·10⁸ blocks, an
//! 18 GB f32 table whose build once aborted the process on a 33.8 GB allocation. [`TableEstimate::table_bytes`] is the
//! file's layout (the format's own section counts, [`SectionKind::expected_count`]) from these
//! counts, so it is exact but for the collision grid, whose cell count and per-cell candidate
//! lists are known only once it is built: the estimate takes their bounds
//! ([`CELLS_PER_SURFACE_VERTEX`] cells per surface vertex, up to 4³ list cells per cell and
//! 343 list entries per surface triangle: the format's `cell-triangle-start` and
//! `cell-triangle`) and is above the real size by less than `2080·Vs + 1372·Ts + 32` bytes
//! (`Vs` surface vertices, `Ts` surface triangles), never below. A tensor-mass table is linear in the mesh; its edge and mesh-triangle counts
//! come from Euler's formula for a solid without holes (`E = V + F_all − T − 1`,
//! `F_all = (4T + F_boundary)/2`), exact for such a mesh, off by a few edges otherwise.
//!
//! Peak working memory of the build (bytes), from the same counts:
//! - pre-computed: the compliance in f64 while it is written (`72·B`), the table's sections and
//!   the file (`2 × table`), a batch of 64 right-hand sides (`3F × 192` f64) and
//!   [`BUILD_BYTES_PER_VERTEX`] per vertex; the sparse Cholesky factor's fill is not included
//!   (known only once factorized; far smaller than the blocks when `S` is large);
//! - tensor-mass: the arrays in f64 (the table's size at 8-byte scalars), the sections and the
//!   file (`2 × table`) and [`BUILD_BYTES_PER_VERTEX`] per vertex.
//!
//! [`SizeLimits::check`] refuses a table above [`MAX_TABLE_FILE_BYTES`] (no reader would load
//! it) or above the caller's `--max-table-bytes`, and a build whose peak exceeds the memory
//! available ([`mem_available_bytes`]): one line naming the estimate and the alternatives.
//!
//! [`SectionKind::expected_count`]: palpate_kernel::table::format::SectionKind::expected_count

use bytemuck::Zeroable;
use palpate_kernel::table::format::{RawHeader, SectionKind, TableKind};

use super::collision::{CELLS_PER_SURFACE_VERTEX, collision_index};
use super::file::{Precision, layout};
use super::options::{BuildOptions, TableKindOptions};
use crate::limits::{MAX_TABLE_FILE_BYTES, human_bytes, mem_available_bytes};
use crate::mesh::{MeshReport, Surface, TetMesh};

/// Working memory of a build per mesh vertex besides its arrays, bytes: the mesh (24 bytes of
/// position, ~6 tets of 16), the stiffness matrix's pattern and values (~15 blocks of 9 values
/// and row indices per free vertex, 2.2 kB), the orderings, the surface and the collision index.
/// A generous round figure: it matters only for meshes whose table is small.
pub const BUILD_BYTES_PER_VERTEX: u64 = 4096;

/// Scalars of the sparse Cholesky factor per free DOF assumed by a hierarchical build's peak
/// (AMD fill of a tetrahedral mesh's stiffness: about 150–400 per DOF from 10k to 200k tets;
/// measured in docs/tables.md, "Hierarchical tables").
const FACTOR_SCALARS_PER_DOF: u64 = 500;

/// Bytes of one f64 3×3 block: the compliance as computed, before it is rounded for the file.
const F64_BLOCK_BYTES: u64 = 72;

/// Touchable vertices per batch of the Cholesky solves (3 right-hand sides each, f64).
const BATCH_VERTICES: u64 = super::compliance::BATCH_VERTICES as u64;

/// The counts a table's size follows from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TableCounts {
    /// Mesh vertices (`N`).
    pub vertices: u64,
    /// Vertices some tet uses.
    pub referenced_vertices: u64,
    /// Tets.
    pub tets: u64,
    /// Free vertices (`F`).
    pub free: u64,
    /// Touchable vertices (`S`): free vertices of the boundary surface.
    pub touchable: u64,
    /// Boundary surface triangles.
    pub surface_triangles: u64,
    /// Distinct vertices of the boundary surface triangles (`Vs`).
    pub surface_vertices: u64,
    /// Connection nodes (`c`) of an interface table (RR-3510 §6.2); zero
    /// for the other kinds.
    pub connections: u64,
}

impl TableCounts {
    /// The counts of `mesh` (its reader's `report`) with the vertices `fixed` (one flag per
    /// vertex) and boundary `surface`: what a build knows before computing any array.
    pub fn of(mesh: &TetMesh, report: &MeshReport, fixed: &[bool], surface: &Surface) -> Self {
        let count = |n: usize| n as u64;
        let free_surface = surface
            .vertices
            .iter()
            .filter(|&&v| fixed.get(v as usize) == Some(&false))
            .count();
        Self {
            vertices: count(mesh.positions.len()),
            referenced_vertices: count(
                mesh.positions
                    .len()
                    .saturating_sub(report.unreferenced_vertices.len()),
            ),
            tets: count(mesh.tets.len()),
            free: count(fixed.iter().filter(|&&f| !f).count()),
            touchable: count(free_surface),
            surface_triangles: count(surface.triangles.len()),
            surface_vertices: count(surface.vertices.len()),
            connections: 0,
        }
    }
}

/// A table's estimated size and its build's peak memory.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TableEstimate {
    /// Which table.
    pub kind: TableKind,
    /// Its stored float width.
    pub precision: Precision,
    /// The counts it is estimated from.
    pub counts: TableCounts,
    /// Compliance blocks `S(S+1)/2 + (F−S)·S` (pre-computed; 0 for tensor-mass), saturating.
    pub blocks: u64,
    /// The table file's size, bytes (module doc: exact but for the grid), saturating at
    /// `u64::MAX` (a count beyond the format's `u32`).
    pub table_bytes: u64,
    /// The build's peak working memory, bytes (module doc), saturating.
    pub peak_bytes: u64,
    /// A compressed pre-computed table (`--compress`): [`Self::table_bytes`] is the f32
    /// table's, a bound of the compressed one's, which the f32 table is built beside.
    pub compressed: bool,
    /// A hierarchical table (`--compress hmatrix`): [`Self::table_bytes`] is its own
    /// estimate (`Self::hierarchical`), not the f32 table's.
    pub hierarchical: bool,
}

impl TableEstimate {
    /// The estimate of the table `options` describe, for `mesh` with `fixed` vertices and
    /// boundary `surface` ([`TableCounts::of`]).
    pub fn of_build(
        mesh: &TetMesh,
        report: &MeshReport,
        options: &BuildOptions,
        fixed: &[bool],
        surface: &Surface,
    ) -> Self {
        let (kind, compressed) = match options.kind {
            TableKindOptions::Precomputed { compression, .. } => {
                (TableKind::Precomputed, compression.is_some())
            }
            TableKindOptions::TensorMass { .. } => (TableKind::TensorMass, false),
        };
        let counts = TableCounts::of(mesh, report, fixed, surface);
        let mut estimate = Self::new(kind, options.precision, counts);
        if let TableKindOptions::Precomputed {
            compression: Some(c),
            ..
        } = options.kind
            && c.code.is_hierarchical()
        {
            return estimate.hierarchical(
                mesh,
                fixed,
                surface,
                c.code == super::compress::BlockCode::HmatrixQ16,
            );
        }
        if compressed {
            // The f32 table's size bounds the compressed one's (`describe`
            // says so); its build also holds the draft, the final table and
            // the two aligned copies its errors are measured on.
            estimate.compressed = true;
            estimate.peak_bytes = estimate
                .peak_bytes
                .saturating_add(estimate.table_bytes.saturating_mul(4));
        }
        estimate
    }

    /// The estimate of a hierarchical table (`--compress hmatrix|hmatrix-q16`, `q16` for
    /// the latter) from `self`, the dense
    /// table's: the dense compliance sections replaced by the hierarchy
    /// ([`super::hmatrix::estimate`]: its partition, every far block at
    /// [`super::hmatrix::ESTIMATE_RANK`]) and one interior scale per touchable vertex. Peak:
    /// the Cholesky factor (about [`FACTOR_SCALARS_PER_DOF`] scalars per free DOF), one batch
    /// of columns (`3F × 3b` f64, `b` ≤ 2 × 64 vertices), the hierarchy as built (f64), the
    /// table and its draft, and [`BUILD_BYTES_PER_VERTEX`] per vertex, plus half of that.
    pub(crate) fn hierarchical(
        self,
        mesh: &TetMesh,
        fixed: &[bool],
        surface: &Surface,
        q16: bool,
    ) -> Self {
        let c = &self.counts;
        let points: Vec<[f64; 3]> = surface
            .vertices
            .iter()
            .filter(|&&v| fixed.get(v as usize) == Some(&false))
            .map(|&v| mesh.positions[v as usize])
            .collect();
        let scalar = u64::from(self.precision.scalar_bytes());
        // q16: two bytes per number, a scale pair per block.
        let (number, pair) = if q16 { (2, 2 * scalar) } else { (scalar, 0) };
        let (data, other) = super::hmatrix::estimate(&points, pair);
        let dense = self.blocks.saturating_mul(9 * scalar);
        let table = self
            .table_bytes
            .saturating_sub(dense)
            .saturating_add(data.saturating_mul(number))
            .saturating_add(other)
            .saturating_add(c.touchable.saturating_mul(scalar));
        let dof = c.free.saturating_mul(3);
        let factor = dof.saturating_mul(FACTOR_SCALARS_PER_DOF * 8);
        let batch = dof.saturating_mul(3 * 2 * BATCH_VERTICES * 8);
        let terms = factor
            .saturating_add(batch)
            .saturating_add(data.saturating_mul(8))
            .saturating_add(table.saturating_mul(2))
            .saturating_add(c.vertices.saturating_mul(BUILD_BYTES_PER_VERTEX));
        // The far blocks' factors while they accumulate and the SVDs' workspaces, not
        // modelled: a 50 % margin (peak RSS 256 MB and 767 MB measured against 190 MB and
        // 536 MB of the terms, on organs of 22.8k and 72.1k tets).
        let peak = terms.saturating_add(terms / 2);
        Self {
            table_bytes: table,
            peak_bytes: peak,
            compressed: true,
            hierarchical: true,
            ..self
        }
    }

    /// The estimate of a table of `kind` in `precision` for `mesh` with `fixed` vertices and
    /// boundary `surface` (no unreferenced vertex counted), a pre-computed table's collision
    /// grid built (linear in the surface) so that its size is the file's exactly rather than
    /// the grid's bound: what a hybrid build checks and `scene plan` reports.
    pub fn of_surface(
        kind: TableKind,
        precision: Precision,
        mesh: &TetMesh,
        fixed: &[bool],
        surface: &Surface,
        tool_radius_m: f64,
    ) -> Self {
        let counts = TableCounts::of(mesh, &MeshReport::default(), fixed, surface);
        let estimate = Self::new(kind, precision, counts);
        if kind != TableKind::Precomputed {
            return estimate;
        }
        let index = collision_index(
            &mesh.positions,
            &surface.triangles,
            tool_radius_m,
            precision,
        );
        let grid = GridCounts {
            cells: index.cell_start.len() as u64 - 1,
            list_starts: index.cell_triangle_start.len() as u64,
            list_entries: index.cell_triangle.len() as u64,
        };
        let exact = layout_bytes(kind, precision, &counts, Some(&grid)).unwrap_or(u64::MAX);
        // The peak holds the table twice (module doc): take the bound's excess off it.
        let excess = estimate.table_bytes.saturating_sub(exact);
        Self {
            table_bytes: exact,
            peak_bytes: estimate.peak_bytes.saturating_sub(excess.saturating_mul(2)),
            ..estimate
        }
    }

    /// The estimate of a table of `kind` stored in `precision` for `counts`.
    pub fn new(kind: TableKind, precision: Precision, counts: TableCounts) -> Self {
        let c = counts;
        let surface_blocks = c.touchable.saturating_mul(c.touchable.saturating_add(1)) / 2;
        let interior_blocks = c
            .free
            .saturating_sub(c.touchable)
            .saturating_mul(c.touchable);
        let blocks = surface_blocks.saturating_add(interior_blocks);
        let per_vertex = c.vertices.saturating_mul(BUILD_BYTES_PER_VERTEX);
        let (table_bytes, peak_bytes) = match kind {
            TableKind::Precomputed => {
                let table = file_bytes(kind, precision, &c);
                // 3F rows of f64 times 3 columns per vertex of the batch.
                let batch = c
                    .free
                    .saturating_mul(3 * 3 * 8)
                    .saturating_mul(c.touchable.min(BATCH_VERTICES));
                let peak = blocks
                    .saturating_mul(F64_BLOCK_BYTES)
                    .saturating_add(table.saturating_mul(2))
                    .saturating_add(batch)
                    .saturating_add(per_vertex);
                (table, peak)
            }
            TableKind::TensorMass => {
                let table = file_bytes(kind, precision, &c);
                let arrays = file_bytes(kind, Precision::F64, &c);
                let peak = arrays
                    .saturating_add(table.saturating_mul(2))
                    .saturating_add(per_vertex);
                (table, peak)
            }
            TableKind::Interface => {
                let table = file_bytes(kind, precision, &c);
                // The dense right-hand sides of the condensation: 3F rows of
                // f64, 3c + 1 columns, plus the f64 blocks before rounding.
                let rhs = c
                    .free
                    .saturating_mul(3 * 8)
                    .saturating_mul(c.connections.saturating_mul(3).saturating_add(1));
                let peak = rhs
                    .saturating_mul(2)
                    .saturating_add(table.saturating_mul(2))
                    .saturating_add(per_vertex);
                (table, peak)
            }
        };
        Self {
            kind,
            precision,
            counts,
            blocks: if kind == TableKind::Precomputed {
                blocks
            } else {
                0
            },
            table_bytes,
            peak_bytes,
            compressed: false,
            hierarchical: false,
        }
    }

    /// One line for people: the table's size and the build's peak memory.
    pub fn describe(&self) -> String {
        let c = &self.counts;
        let what = match self.kind {
            TableKind::Precomputed => format!(
                "the pre-computed table ({} compliance blocks: {} free x {} touchable vertices, {})",
                self.blocks,
                c.free,
                c.touchable,
                precision_name(self.precision)
            ),
            TableKind::TensorMass => format!(
                "the tensor-mass table ({} vertices, {} tets, {})",
                c.vertices,
                c.tets,
                precision_name(self.precision)
            ),
            TableKind::Interface => format!(
                "the interface table ({} connection nodes x {} free pre-computed vertices, {})",
                c.connections,
                c.free,
                precision_name(self.precision)
            ),
        };
        let compressed = if self.hierarchical {
            format!(
                " (hierarchical, far blocks estimated at rank {})",
                super::hmatrix::ESTIMATE_RANK
            )
        } else if self.compressed {
            " (uncompressed; compressed, about half that or less)".to_owned()
        } else {
            String::new()
        };
        format!(
            "{what} would be {}{compressed}, and its build needs about {} of memory",
            human_bytes(self.table_bytes),
            human_bytes(self.peak_bytes)
        )
    }
}

fn precision_name(p: Precision) -> &'static str {
    match p {
        Precision::F32 => "f32",
        Precision::F64 => "f64",
    }
}

/// The file size of a table of `kind` in `precision` for counts `c`: the writer's layout
/// ([`layout`]: header, directory, sections aligned to 16 bytes, CRC) with
/// the format's section counts. The grid's cell count is its bound. `u64::MAX` when a count
/// does not fit the header's `u32` or the sum overflows.
fn file_bytes(kind: TableKind, precision: Precision, c: &TableCounts) -> u64 {
    layout_bytes(kind, precision, c, None).unwrap_or(u64::MAX)
}

/// A built collision grid's counts, which replace their bounds in [`layout_bytes`].
struct GridCounts {
    /// Grid cells.
    cells: u64,
    /// Entries of `cell-triangle-start` (list cells + 1).
    list_starts: u64,
    /// Entries of `cell-triangle`.
    list_entries: u64,
}

fn layout_bytes(
    kind: TableKind,
    precision: Precision,
    c: &TableCounts,
    grid: Option<&GridCounts>,
) -> Option<u64> {
    let u32_of = |x: u64| u32::try_from(x).ok();
    let scalar_bytes = precision.scalar_bytes();
    let mut header = RawHeader {
        vertex_count: u32_of(c.vertices)?,
        tet_count: u32_of(c.tets)?,
        triangle_count: u32_of(c.surface_triangles)?,
        ..RawHeader::zeroed()
    };
    match kind {
        TableKind::Precomputed => {
            header.free_count = u32_of(c.free)?;
            header.touchable_count = u32_of(c.touchable)?;
            header.surface_vertex_count = u32_of(c.surface_vertices)?;
            header.grid_cell_count = u32_of(match grid {
                Some(g) => g.cells,
                None => c
                    .surface_vertices
                    .max(1)
                    .checked_mul(CELLS_PER_SURFACE_VERTEX as u64)?,
            })?;
        }
        TableKind::TensorMass => {
            // Every face once: each interior face is shared by two tets.
            let mesh_triangles = c.tets.checked_mul(4)?.checked_add(c.surface_triangles)? / 2;
            // Euler's formula of a solid without holes: V − E + F − T = 1.
            let edges = c
                .referenced_vertices
                .checked_add(mesh_triangles)?
                .saturating_sub(c.tets.checked_add(1)?);
            header.edge_count = u32_of(edges)?;
            header.mesh_triangle_count = mesh_triangles;
        }
        TableKind::Interface => {
            header.free_count = u32_of(c.free)?;
            header.touchable_count = u32_of(c.touchable)?;
            header.connection_count = u32_of(c.connections)?;
        }
    }
    let sizes = kind
        .sections()
        .iter()
        .map(|&section| {
            let count = match (section, grid) {
                (SectionKind::CellTriangleStart, Some(g)) => g.list_starts,
                (SectionKind::CellTriangle, Some(g)) => g.list_entries,
                _ => section.expected_count(&header)?,
            };
            count.checked_mul(u64::from(section.elem_bytes(scalar_bytes)))
        })
        .collect::<Option<Vec<u64>>>()?;
    layout(&sizes).map(|(_, file_len)| file_len)
}

/// What a table build may produce and use, checked by [`SizeLimits::check`] before the arrays
/// are computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SizeLimits {
    /// Largest table, bytes (`tables build --max-table-bytes`); [`MAX_TABLE_FILE_BYTES`] applies
    /// in any case.
    pub max_table_bytes: Option<u64>,
    /// Memory the build may use, bytes; `None`: not checked.
    pub available_bytes: Option<u64>,
    /// Print the estimate on stderr (one line) when the build goes ahead.
    pub print_estimate: bool,
}

impl SizeLimits {
    /// The limits of every build: [`MAX_TABLE_FILE_BYTES`] and the memory available now
    /// ([`mem_available_bytes`]), nothing printed.
    pub fn system() -> Self {
        Self {
            max_table_bytes: None,
            available_bytes: mem_available_bytes(),
            print_estimate: false,
        }
    }

    /// Refuses `estimate` above a limit, with one line starting with `source` (the mesh) that
    /// gives the estimate, the limit and what to do instead; otherwise prints the estimate if
    /// asked.
    pub fn check(&self, estimate: &TableEstimate, source: &str) -> anyhow::Result<()> {
        let source = if source.is_empty() {
            String::new()
        } else {
            format!("{source}: ")
        };
        let Some(reason) = self.refusal(estimate) else {
            if self.print_estimate {
                crate::output::stderr::line(&format!("{source}estimate: {}", estimate.describe()));
            }
            return Ok(());
        };
        anyhow::bail!(
            "{source}{}; {reason}: refused before building; {}",
            estimate.describe(),
            instead(estimate.kind)
        )
    }

    /// Why `estimate` is above a limit (the limit, for people), or `None` when it fits.
    pub fn refusal(&self, estimate: &TableEstimate) -> Option<String> {
        let table = estimate.table_bytes;
        let over_max = self.max_table_bytes.filter(|&max| table > max);
        let short_of = self
            .available_bytes
            .filter(|&available| estimate.peak_bytes > available);
        if table > MAX_TABLE_FILE_BYTES {
            Some(format!(
                "the table is above the largest table file, {} (MAX_TABLE_FILE_BYTES)",
                human_bytes(MAX_TABLE_FILE_BYTES)
            ))
        } else if let Some(max) = over_max {
            Some(format!("the table is above --max-table-bytes {max} bytes"))
        } else {
            short_of.map(|available| {
                format!(
                    "only {} of memory is available (MemAvailable)",
                    human_bytes(available)
                )
            })
        }
    }
}

/// What to do instead of a table of `kind` refused for its size.
pub fn instead(kind: TableKind) -> &'static str {
    match kind {
        TableKind::Precomputed => {
            "use the tensor-mass model (tables build --kind tensor-mass, or [model] kind = \"dynamic\" in a scene), a coarser mesh, or fix more of the surface (fewer touchable vertices)"
        }
        TableKind::TensorMass => "use a coarser mesh",
        TableKind::Interface => {
            "make the dynamic zones smaller or simpler (fewer connection nodes), or use a coarser mesh"
        }
    }
}

//! The three tables of a hybrid model (RR-3510 §6.2): the pre-computed
//! region's (connection nodes fixed), the tensor-mass region's (its own
//! vertex numbering) and the interface that condenses the former onto the
//! connection nodes.

use anyhow::{Context, bail};
use bytemuck::Zeroable;
use palpate_kernel::table::format::{FIXED_SLOT, RawHeader, SectionKind, TableKind};
use palpate_kernel::table::{InterfaceTable, TensorMassTable};
use palpate_kernel::{PrecomputedTable, Real};

use super::condense::{Condensed, condense};
use super::estimate::{HybridEstimate, PrecomputedRegion};
use super::hmatrix::{InterfaceCompression, compress_condensed};
use super::split::RegionSplit;
use crate::fem::assembly::FreeOrdering;
use crate::fem::element::shape_gradients;
use crate::fem::material::{Material, TetMaterials};
use crate::fix::{FixPredicate, fixed_vertices};
use crate::mesh::{MeshReport, TetMesh, boundary_surface};
use crate::table::build::{BuildOptions, BuiltTable, Stages, TableKindOptions, precomputed};
use crate::table::compliance::Solver;
use crate::table::compress::{BlockCode, Compression, ContactBlocks};
use crate::table::estimate::SizeLimits;
use crate::table::file::{Precision, Section, write_container};
use crate::table::hmatrix::clustered;
use crate::table::load::TableFile;
use crate::table::tensor_mass::{TensorMassArrays, write_tensor_mass_table};

/// What a hybrid build needs besides the mesh and the split.
#[derive(Clone, Debug)]
pub struct HybridOptions {
    /// The materials (one, or one per tet of the whole mesh), the fixed
    /// predicates and the precision, as a pre-computed build takes them.
    pub build: BuildOptions,
    /// Mass density, kg/m³ (the tensor-mass region's masses and the
    /// pre-computed region's gravity load).
    pub density_kg_m3: f64,
    /// Gravity on the pre-computed region, m/s² (built into its load; the
    /// tensor-mass region takes it as a run parameter).
    pub gravity_m_s2: [f64; 3],
    /// Point loads `(mesh vertex, force N)` on free vertices of the
    /// pre-computed region, built into its load (a point load on the
    /// tensor-mass region is an external force of its model).
    pub point_loads: Vec<(u32, [f64; 3])>,
    /// Which tets' mass the connection nodes carry.
    pub connection_mass: ConnectionMass,
    /// The interface's condensed stiffness stored hierarchically
    /// (`[tables] compress = "hmatrix"`), `None`: dense.
    pub interface_compression: Option<InterfaceCompression>,
    /// The pre-computed region's table hierarchical too (`[tables] compress = "hmatrix"` on a
    /// scene: a hierarchical pre-computed table at the tolerance of
    /// [`Self::interface_compression`], which it needs), and the interface's response stored
    /// over the region's touchable vertices only (section `touchable-response`): the region
    /// then moves its touchable vertices only, as a hierarchical pre-computed table does. f32
    /// tables only (a hierarchical table's precision).
    pub compress_region: bool,
    /// What the tables and the build may take ([`SizeLimits::system`] by default), checked
    /// against their estimate ([`HybridEstimate`]) before anything is built.
    pub limits: SizeLimits,
}

/// The lumped mass of the connection nodes in the tensor-mass region.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ConnectionMass {
    /// Both regions' tets (the default): the whole mesh's lumped mass, so
    /// the coupling does not lower the stable step (README, "The hybrid
    /// model": measured, and bounded by the all-tensor-mass model's).
    #[default]
    AllTets,
    /// The tensor-mass region's tets only, as the region alone would have:
    /// the condensed stiffness then stiffens the connection nodes without
    /// their mass, which lowers the stable step (kept to measure it).
    DynamicTetsOnly,
}

impl HybridOptions {
    /// Options of one `material` with no load and the default connection
    /// mass (per-tet materials: [`Self::with_tet_materials`]).
    pub fn new(
        material: Material,
        density_kg_m3: f64,
        fix: Vec<FixPredicate>,
        precision: Precision,
    ) -> Self {
        Self {
            build: BuildOptions::precomputed(material, fix, Solver::Cholesky, precision),
            density_kg_m3,
            gravity_m_s2: [0.0; 3],
            point_loads: Vec::new(),
            connection_mass: ConnectionMass::AllTets,
            interface_compression: None,
            compress_region: false,
            limits: SizeLimits::system(),
        }
    }

    /// The options of a tensor-mass table's `build` (its materials, one or
    /// per tet, density, supports and precision), with no load and the
    /// default connection mass; an error for pre-computed options (no
    /// density).
    pub fn of_tensor_mass(build: &BuildOptions) -> anyhow::Result<Self> {
        let TableKindOptions::TensorMass { density_kg_m3 } = build.kind else {
            bail!("a hybrid needs the options of a tensor-mass table (its density)");
        };
        Ok(Self {
            build: build.clone(),
            density_kg_m3,
            gravity_m_s2: [0.0; 3],
            point_loads: Vec::new(),
            connection_mass: ConnectionMass::AllTets,
            interface_compression: None,
            compress_region: false,
            limits: SizeLimits::system(),
        })
    }

    /// The same with one material per tet of the whole mesh.
    pub fn with_tet_materials(self, materials: TetMaterials) -> Self {
        Self {
            build: self.build.with_tet_materials(materials),
            ..self
        }
    }
}

/// The three tables and how the mesh was split.
pub struct HybridTables {
    /// The pre-computed region's table, connection nodes fixed, mesh numbering.
    pub precomputed: TableFile,
    /// The tensor-mass region's table, [`RegionSplit::dynamic_vertex`] numbering.
    pub dynamic: TableFile,
    /// The interface table.
    pub interface: TableFile,
    /// The split.
    pub split: RegionSplit,
    /// The pre-computed table's build summary.
    pub precomputed_summary: BuiltTable,
}

/// Builds the hybrid tables of `mesh` with the tets flagged in
/// `dynamic_tet` in the tensor-mass region.
///
/// The connection nodes carry the lumped mass of all their tets (both
/// regions): the pre-computed region is massless in its model, so the mass
/// its tets lump onto the connection nodes is given to the tensor-mass
/// region, which keeps the whole mesh's lumped mass matrix on the vertices
/// it integrates (and the whole mesh's gravity load with the pre-computed
/// region's built in). This also keeps the stable step of the hybrid no
/// smaller than the all-tensor-mass model's: the condensed stiffness is
/// bounded by the pre-computed tets' own stiffness on the connection
/// nodes, and the mass is the same (README, "The hybrid model").
pub fn build_hybrid(
    mesh: &TetMesh,
    report: &MeshReport,
    dynamic_tet: &[bool],
    options: &HybridOptions,
) -> anyhow::Result<HybridTables> {
    let source = &report.source;
    let build = &options.build;
    let materials = build.materials_for(mesh.tets.len())?;
    let Prepared {
        fixed,
        split,
        region,
        ..
    } = prepare(mesh, report, dynamic_tet, options)?;
    let pmaterials = materials.subset(region_tets(&split, false));
    let pbuild = region_build_options(options)?;
    let (precomputed_summary, ordering) =
        precomputed_table(mesh, report, &fixed, &region, &pmaterials, &pbuild)?;

    // Lumped masses of the pre-computed region's tets, and its load.
    let precomputed_mass = lumped_mass(mesh, &split, options.density_kg_m3, false);
    let load_n = precomputed_load(&precomputed_mass, &region.fixed, options, source)?;
    let mut condensed = condense(
        &mesh.positions,
        &region.mesh.tets,
        &pmaterials,
        &ordering,
        &split.connection,
        &load_n,
    )
    .with_context(|| format!("{source}: condensing the pre-computed region"))?;
    if options.connection_mass == ConnectionMass::DynamicTetsOnly {
        // The connection nodes' share of the pre-computed tets' gravity,
        // which their tensor-mass masses do not carry in this mode.
        for (force, &v) in condensed.load_force.iter_mut().zip(&split.connection) {
            for (f, g) in force.iter_mut().zip(options.gravity_m_s2) {
                *f += precomputed_mass[v as usize] * g;
            }
        }
    }

    let dynamic = dynamic_table(mesh, &split, &fixed, &materials, &precomputed_mass, options);
    let checksums = [&precomputed_summary.bytes, &dynamic].map(|bytes| trailer(bytes));
    let interface = write_interface_table(
        mesh, &split, &ordering, &condensed, &materials, checksums, options,
    )
    .with_context(|| format!("{source}: the interface table"))?;
    let tables = HybridTables {
        precomputed: TableFile::from_bytes(&precomputed_summary.bytes),
        dynamic: TableFile::from_bytes(&dynamic),
        interface: TableFile::from_bytes(&interface),
        split,
        precomputed_summary: BuiltTable {
            bytes: Vec::new(),
            ..precomputed_summary
        },
    };
    let loaded = match build.precision {
        Precision::F32 => tables.check::<f32>(),
        Precision::F64 => tables.check::<f64>(),
    };
    loaded.with_context(|| {
        format!("{source}: the built hybrid tables fail Palpate's own load check")
    })?;
    Ok(tables)
}

/// The tets of the tensor-mass region (`dynamic`) or of the pre-computed one.
fn region_tets(split: &RegionSplit, dynamic: bool) -> impl Iterator<Item = usize> + '_ {
    let flags = &split.dynamic_tet;
    (0..flags.len()).filter(move |&t| flags[t] == dynamic)
}

/// The pre-computed region's build options: the hybrid's, with the
/// hierarchical compression of [`HybridOptions::compress_region`] (which
/// needs the interface's compression, for its tolerance, and f32 tables).
fn region_build_options(options: &HybridOptions) -> anyhow::Result<BuildOptions> {
    if !options.compress_region {
        return Ok(options.build.clone());
    }
    let Some(compression) = options.interface_compression else {
        bail!("a hierarchical pre-computed region needs the interface compressed (its tolerance)");
    };
    if options.build.precision != Precision::F32 {
        bail!("a hierarchical pre-computed region is stored in f32: build the hybrid in f32");
    }
    Ok(options.build.clone().with_compression(Some(Compression {
        code: BlockCode::Hmatrix,
        drop_below: 0.0,
        contact: ContactBlocks::Coded,
        tolerance: compression.tolerance,
    })))
}

/// The pre-computed region's table (its tets with `pmaterials`, the
/// connection nodes fixed; Cholesky; hierarchical if `build` asks), with its
/// build summary counting the whole mesh's `fixed` vertices, and the
/// region's free ordering (a hierarchical table's: its touchable vertices in
/// its cluster tree's order, checked against the table built).
fn precomputed_table(
    mesh: &TetMesh,
    report: &MeshReport,
    fixed: &[bool],
    region: &PrecomputedRegion,
    pmaterials: &TetMaterials,
    build: &BuildOptions,
) -> anyhow::Result<(BuiltTable, FreeOrdering)> {
    let summary = BuiltTable {
        bytes: Vec::new(),
        fixed_by_predicate: fixed.iter().filter(|&&f| f).count(),
        fixed_unreferenced: report.unreferenced_vertices.len(),
        free_count: region.fixed.iter().filter(|&&f| !f).count(),
        touchable_count: 0,
        edge_count: 0,
        arrays_time: core::time::Duration::ZERO,
    };
    let preport = MeshReport {
        source: format!("{} (pre-computed region)", report.source),
        ..MeshReport::default()
    };
    let stages = Stages {
        fixed: &region.fixed,
        surface: &region.surface,
        materials: pmaterials,
    };
    let built = precomputed(
        &region.mesh,
        &preport,
        build,
        Solver::Cholesky,
        &stages,
        summary,
    )?;
    let ordering = FreeOrdering::new(
        mesh.positions.len(),
        &region.fixed,
        &region.surface.vertices,
    );
    let hierarchical = matches!(
        build.kind,
        TableKindOptions::Precomputed { compression: Some(c), .. } if c.code.is_hierarchical()
    );
    if !hierarchical {
        return Ok((built, ordering));
    }
    let (_, ordering) = clustered(&mesh.positions, ordering);
    let table = TableFile::from_bytes(&built.bytes);
    let table = PrecomputedTable::<f32>::load(table.bytes())
        .context("the hierarchical pre-computed region fails Palpate's own load check")?;
    anyhow::ensure!(
        table.free_vertices() == ordering.free_vertex.as_slice(),
        "the hierarchical pre-computed region's free ordering is not the interface's (a bug: \
         please report it)"
    );
    Ok((built, ordering))
}

/// Per vertex, the lumped mass (kg) of the tensor-mass region's tets
/// (`dynamic`) or of the pre-computed region's: a quarter of each tet's
/// `density_kg_m3 × volume` on each of its vertices.
fn lumped_mass(mesh: &TetMesh, split: &RegionSplit, density_kg_m3: f64, dynamic: bool) -> Vec<f64> {
    let mut m = vec![0.0f64; mesh.positions.len()];
    for (tet, &d) in mesh.tets.iter().zip(&split.dynamic_tet) {
        if d == dynamic {
            let (_, volume) = shape_gradients(&tet.map(|v| mesh.positions[v as usize]));
            for &v in tet {
                m[v as usize] += density_kg_m3 * volume / 4.0;
            }
        }
    }
    m
}

/// The pre-computed region's load, N per vertex: the gravity of its
/// `precomputed_mass` and the point loads of `options`, each on a free
/// vertex of the region (`pfixed` false), else refused.
fn precomputed_load(
    precomputed_mass: &[f64],
    pfixed: &[bool],
    options: &HybridOptions,
    source: &str,
) -> anyhow::Result<Vec<[f64; 3]>> {
    let mut load_n: Vec<[f64; 3]> = precomputed_mass
        .iter()
        .map(|&m| options.gravity_m_s2.map(|g| m * g))
        .collect();
    for &(v, force) in &options.point_loads {
        let Some(load) = load_n.get_mut(v as usize).filter(|_| !pfixed[v as usize]) else {
            bail!(
                "{source}: point load on vertex {v}, not a free vertex of the pre-computed region"
            );
        };
        for (l, f) in load.iter_mut().zip(force) {
            *l += f;
        }
    }
    Ok(load_n)
}

/// The tensor-mass region's table (its own vertex numbering), the
/// connection nodes carrying the pre-computed tets' mass too
/// ([`ConnectionMass::AllTets`]).
fn dynamic_table(
    mesh: &TetMesh,
    split: &RegionSplit,
    fixed: &[bool],
    materials: &TetMaterials,
    precomputed_mass: &[f64],
    options: &HybridOptions,
) -> Vec<u8> {
    let dmesh = split.dynamic_mesh(mesh);
    let dfixed: Vec<bool> = split
        .dynamic_vertex
        .iter()
        .map(|&v| fixed[v as usize])
        .collect();
    let dmaterials = materials.subset(region_tets(split, true));
    let mut arrays = TensorMassArrays::new(&dmesh, &dmaterials, options.density_kg_m3, dfixed);
    if options.connection_mass == ConnectionMass::AllTets {
        for &v in &split.connection {
            if let Some(d) = split.dynamic_index[v as usize] {
                arrays.masses_kg[d as usize] += precomputed_mass[v as usize];
            }
        }
    }
    let dsurface = boundary_surface(&dmesh);
    write_tensor_mass_table(
        &dmesh,
        &dsurface.triangles,
        &arrays,
        options.build.precision,
    )
}

impl HybridTables {
    /// Loads the three tables with the kernel's loaders.
    pub fn check<T: Real>(&self) -> anyhow::Result<()> {
        PrecomputedTable::<T>::load(self.precomputed.bytes()).context("pre-computed region")?;
        TensorMassTable::<T>::load(self.dynamic.bytes()).context("tensor-mass region")?;
        InterfaceTable::<T>::load(self.interface.bytes()).context("interface")?;
        Ok(())
    }
}

/// What [`build_hybrid`] knows before it builds a table: the scene's fixed vertices, the split,
/// the pre-computed region and the estimate, checked.
struct Prepared {
    fixed: Vec<bool>,
    split: RegionSplit,
    region: PrecomputedRegion,
    estimate: HybridEstimate,
}

/// The split of `mesh` by `dynamic_tet` and the estimate of its tables, checked against
/// `options.limits` (the estimate printed if they ask): every refusal of a hybrid that does not
/// need its arrays, linear in the mesh.
fn prepare(
    mesh: &TetMesh,
    report: &MeshReport,
    dynamic_tet: &[bool],
    options: &HybridOptions,
) -> anyhow::Result<Prepared> {
    let source = &report.source;
    let build = &options.build;
    let (fixed, _) = fixed_vertices(&mesh.positions, &build.fix, &report.unreferenced_vertices);
    let split = RegionSplit::new(mesh, &fixed, dynamic_tet).with_context(|| source.clone())?;
    // The pre-computed region: connection nodes and vertices outside it fixed.
    let region = PrecomputedRegion::of(mesh, &split, &fixed);
    if region.fixed.iter().all(|&f| f) {
        bail!(
            "{source}: the pre-computed region has no free vertex (every one is fixed or connects)"
        );
    }
    let estimate = HybridEstimate::of(
        mesh,
        &split,
        &fixed,
        &region,
        build.list_tool_radius_m(),
        build.precision,
    );
    let estimate = match &options.interface_compression {
        Some(compression) => {
            estimate.compressed(mesh, &split, &region, compression, options.compress_region)
        }
        None => estimate,
    };
    estimate.check(&options.limits, source)?;
    Ok(Prepared {
        fixed,
        split,
        region,
        estimate,
    })
}

/// Checks, without building anything, that [`build_hybrid`] of the same arguments would start:
/// the split is a hybrid, the pre-computed region has a free vertex, and the tables' estimate
/// is within `options.limits`. Returns the estimate. For a command that builds hybrids late in
/// a long run (`palpate chart`), before it starts.
pub fn check_hybrid(
    mesh: &TetMesh,
    report: &MeshReport,
    dynamic_tet: &[bool],
    options: &HybridOptions,
) -> anyhow::Result<HybridEstimate> {
    Ok(prepare(mesh, report, dynamic_tet, options)?.estimate)
}

/// Serializes the interface table (`TableKind::Interface`), its condensed
/// stiffness dense or, as `options` ask, hierarchical.
fn write_interface_table(
    mesh: &TetMesh,
    split: &RegionSplit,
    ordering: &FreeOrdering,
    condensed: &Condensed,
    materials: &TetMaterials,
    region_checksums: [u32; 2],
    options: &HybridOptions,
) -> anyhow::Result<Vec<u8>> {
    let material = materials.default_material();
    let header = RawHeader {
        table_kind: TableKind::Interface as u32,
        vertex_count: mesh.positions.len() as u32,
        tet_count: mesh.tets.len() as u32,
        free_count: ordering.free_count() as u32,
        touchable_count: ordering.touchable_count as u32,
        connection_count: split.connection.len() as u32,
        young_pa: material.young_pa,
        poisson: material.poisson,
        density_kg_m3: options.density_kg_m3,
        mesh_hash: mesh.content_hash(),
        ..RawHeader::zeroed()
    };
    let connections: Vec<[u32; 2]> = split
        .connection
        .iter()
        .map(|&v| [v, split.dynamic_index[v as usize].unwrap_or(FIXED_SLOT)])
        .collect();
    let dynamic_vertex: Vec<u32> = split
        .dynamic_index
        .iter()
        .map(|d| d.unwrap_or(FIXED_SLOT))
        .collect();
    let p = options.build.precision;
    let stiffness = match &options.interface_compression {
        None => vec![Section::floats(
            SectionKind::CondensedStiffness,
            &condensed.condensed,
            p,
        )],
        Some(compression) => {
            let points: Vec<[f64; 3]> = split
                .connection
                .iter()
                .map(|&v| mesh.positions[v as usize])
                .collect();
            let h = compress_condensed(&points, &condensed.condensed, compression)?;
            let mut sections = h.hierarchy.sections(p);
            sections.push(Section::ints(SectionKind::HierarchyOrder, &h.order));
            sections
        }
    };
    // The response of every free vertex, or of the touchable ones (the first `S` free
    // indices: their `3S·c` rows lead the row-major `H`) beside a hierarchical region.
    let response = if options.compress_region {
        let rows = 3 * ordering.touchable_count * split.connection.len();
        Section::floats(
            SectionKind::TouchableResponse,
            &condensed.response[..rows],
            p,
        )
    } else {
        Section::floats(SectionKind::ConnectionResponse, &condensed.response, p)
    };
    let mut sections = vec![Section::ints(SectionKind::ConnectionVertex, &connections)];
    sections.extend(stiffness);
    sections.extend([
        response,
        Section::floats(
            SectionKind::LoadDisplacement,
            &condensed.load_displacement,
            p,
        ),
        Section::floats(SectionKind::LoadForce, &condensed.load_force, p),
        Section::ints(SectionKind::DynamicVertex, &dynamic_vertex),
        Section::ints(SectionKind::RegionChecksums, &[region_checksums]),
    ]);
    Ok(write_container(header, p, &sections))
}

/// A table file's CRC-32 trailer (its last 4 bytes, little-endian).
fn trailer(bytes: &[u8]) -> u32 {
    let mut crc = [0u8; 4];
    if let Some(tail) = bytes.len().checked_sub(4).and_then(|at| bytes.get(at..)) {
        crc.copy_from_slice(tail);
    }
    u32::from_le_bytes(crc)
}

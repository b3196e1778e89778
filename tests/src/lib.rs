//! Shared helpers for the workspace integration tests: where the independent
//! reference data lives and how to read it, and the session tests' readers of
//! scene and trajectory text.

use std::path::{Path, PathBuf};

pub mod source;

use palpate::scene::{Keyframe, Scene, ToolState, Trajectory};

/// The independent reference data committed with the tests
/// (`tests/reference/`, see its README for how each file was computed).
pub fn reference_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("reference")
}

/// Small hand-written test files committed with the tests (`tests/data/`).
pub fn data_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("data")
}

/// Reads the TetGen pair `meshes/NAME.node` / `meshes/NAME.ele` of the
/// reference data (0-based indices): vertex positions and tets.
pub fn read_reference_tetgen(name: &str) -> (Vec<[f64; 3]>, Vec<[u32; 4]>) {
    let dir = reference_dir().join("meshes");
    let read = |ext: &str| {
        std::fs::read_to_string(dir.join(format!("{name}.{ext}")))
            .unwrap_or_else(|e| panic!("read {name}.{ext}: {e}"))
    };
    (
        tetgen_rows(&read("node"), "coordinate"),
        tetgen_rows(&read("ele"), "vertex index"),
    )
}

/// The `K` values after the index of each row of a TetGen `.node`/`.ele`
/// text: the first line gives the row count, indices are 0-based and in
/// order, `#` starts a comment.
fn tetgen_rows<T: core::str::FromStr, const K: usize>(text: &str, what: &str) -> Vec<[T; K]> {
    let rows: Vec<Vec<&str>> = text
        .lines()
        .map(|l| l.split('#').next().unwrap_or("").trim())
        .filter(|l| !l.is_empty())
        .map(|l| l.split_whitespace().collect())
        .collect();
    let count: usize = rows[0][0].parse().expect("row count");
    rows[1..=count]
        .iter()
        .enumerate()
        .map(|(i, r)| {
            assert_eq!(
                r[0].parse::<usize>().expect("index"),
                i,
                "0-based, in order"
            );
            core::array::from_fn(|c| {
                r[c + 1]
                    .parse()
                    .unwrap_or_else(|_| panic!("{what} in row {i}"))
            })
        })
        .collect()
}

/// Unit box `[0,1]³` split into `cells` hexahedral cells, 6 Kuhn tets each,
/// exactly as the reference `cube` mesh (reference README): vertex
/// `idx(i,j,k) = i + (nx+1)(j + (ny+1)k)` at `(i/nx, j/ny, k/nz)`; in cell
/// `c0`, for the axis permutations (0,1,2),(0,2,1),(1,0,2),(1,2,0),(2,0,1),
/// (2,1,0) the tet `[c0, c0+e_a, c0+e_a+e_b, c0+e_a+e_b+e_c]`, last two
/// swapped when negative; cells in x-fastest order.
pub fn kuhn_box(cells: [usize; 3]) -> (Vec<[f64; 3]>, Vec<[u32; 4]>) {
    let [nx, ny, nz] = cells;
    let idx = |i: usize, j: usize, k: usize| (i + (nx + 1) * (j + (ny + 1) * k)) as u32;
    let mut positions = Vec::with_capacity((nx + 1) * (ny + 1) * (nz + 1));
    for k in 0..=nz {
        for j in 0..=ny {
            for i in 0..=nx {
                positions.push([
                    i as f64 / nx as f64,
                    j as f64 / ny as f64,
                    k as f64 / nz as f64,
                ]);
            }
        }
    }
    const PERMS: [[usize; 3]; 6] = [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
    ];
    let mut tets = Vec::with_capacity(6 * nx * ny * nz);
    for ck in 0..nz {
        for cj in 0..ny {
            for ci in 0..nx {
                for perm in PERMS {
                    let mut c = [ci, cj, ck];
                    let mut t = [idx(c[0], c[1], c[2]); 4];
                    for (s, &axis) in perm.iter().enumerate() {
                        c[axis] += 1;
                        t[s + 1] = idx(c[0], c[1], c[2]);
                    }
                    let p = t.map(|v| positions[v as usize]);
                    let d = |a: usize| [0, 1, 2].map(|x| p[a][x] - p[0][x]);
                    let (a, b, e) = (d(1), d(2), d(3));
                    let det = a[0] * (b[1] * e[2] - b[2] * e[1])
                        - a[1] * (b[0] * e[2] - b[2] * e[0])
                        + a[2] * (b[0] * e[1] - b[1] * e[0]);
                    if det < 0.0 {
                        t.swap(2, 3);
                    }
                    tets.push(t);
                }
            }
        }
    }
    (positions, tets)
}

/// Vertices on the boundary surface (faces used by exactly one tet),
/// ascending.
pub fn boundary_vertices(vertex_count: usize, tets: &[[u32; 4]]) -> Vec<u32> {
    let mut faces: std::collections::HashMap<[u32; 3], u32> = std::collections::HashMap::new();
    for t in tets {
        for skip in 0..4 {
            let mut f = [0u32; 3];
            let mut n = 0;
            for (i, &v) in t.iter().enumerate() {
                if i != skip {
                    f[n] = v;
                    n += 1;
                }
            }
            f.sort_unstable();
            *faces.entry(f).or_insert(0) += 1;
        }
    }
    let mut on = vec![false; vertex_count];
    for (f, c) in faces {
        if c == 1 {
            for v in f {
                on[v as usize] = true;
            }
        }
    }
    (0..vertex_count as u32)
        .filter(|&v| on[v as usize])
        .collect()
}

/// Parses a JSON file of the reference data (`reference_dir()/rel`).
pub fn read_reference_json(rel: &str) -> serde_json::Value {
    let text = std::fs::read_to_string(reference_dir().join(rel)).expect("read reference JSON");
    serde_json::from_str(&text).expect("parse reference JSON")
}

/// `max_i |a_i - b_i| / max_i |b_i|` (0 when both are all zero).
pub fn rel_max_diff(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    let scale = b.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let diff = a
        .iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    if scale == 0.0 { diff } else { diff / scale }
}

/// The reference cube (`tests/reference/meshes/cube.msh`, E = 5000 Pa,
/// ν = 0.45) with its base `z = 0` fixed, built into a table of `precision`
/// through the same pipeline as `palpate tables build`.
pub fn reference_cube_table(
    precision: palpate::table::file::Precision,
) -> palpate::table::load::TableFile {
    use palpate::table::build::{BuildOptions, build};
    let (mesh, report) =
        palpate::mesh::read_mesh(&reference_dir().join("meshes/cube.msh")).expect("cube.msh");
    let options = BuildOptions::precomputed(
        palpate::fem::material::Material::new(5000.0, 0.45).expect("material"),
        vec!["z<0.001".parse().expect("predicate")],
        palpate::table::compliance::Solver::Cholesky,
        precision,
    );
    let built = build(&mesh, &report, &options).expect("build table");
    palpate::table::load::TableFile::from_bytes(&built.bytes)
}

/// A JSON array of `[x, y, z]` rows as `f64` triples.
pub fn json_rows(v: &serde_json::Value) -> Vec<[f64; 3]> {
    v.as_array()
        .expect("array")
        .iter()
        .map(|row| {
            let r = row.as_array().expect("row");
            [0, 1, 2].map(|i| r[i].as_f64().expect("number"))
        })
        .collect()
}

/// `tests/reference/linear/cube_K.csv`: the global stiffness of `cube`
/// (E = 5000 Pa, ν = 0.45) as `(row, col) → value` (DOF `3·vertex + axis`, N/m).
pub fn read_reference_stiffness() -> std::collections::HashMap<(usize, usize), f64> {
    let text =
        std::fs::read_to_string(reference_dir().join("linear/cube_K.csv")).expect("cube_K.csv");
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("row"))
        .map(|line| {
            let f: Vec<&str> = line.split(',').collect();
            let parse = |i: usize| f[i].trim().parse::<f64>().expect("number");
            ((parse(0) as usize, parse(1) as usize), parse(2))
        })
        .collect()
}

/// Largest `|a − b|` over the entries of two sparse matrices given as
/// `(row, col) → value` (an entry missing on one side counts as zero).
pub fn max_entry_difference(
    a: &std::collections::HashMap<(usize, usize), f64>,
    b: &std::collections::HashMap<(usize, usize), f64>,
) -> f64 {
    let one_way = |x: &std::collections::HashMap<(usize, usize), f64>,
                   y: &std::collections::HashMap<(usize, usize), f64>| {
        x.iter().fold(0.0f64, |worst, (key, v)| {
            worst.max((v - y.get(key).copied().unwrap_or(0.0)).abs())
        })
    };
    one_way(a, b).max(one_way(b, a))
}

/// `mesh` without the tets whose `alive` flag is false (same vertices and
/// numbering): what a model built after a cut should equal.
pub fn live_mesh(mesh: &palpate::mesh::TetMesh, alive: &[bool]) -> palpate::mesh::TetMesh {
    palpate::mesh::TetMesh {
        positions: mesh.positions.clone(),
        tets: mesh
            .tets
            .iter()
            .zip(alive)
            .filter(|(_, a)| **a)
            .map(|(t, _)| *t)
            .collect(),
    }
}

/// The force on the hand of contacts holding vertices at imposed
/// displacements, from one global static linear FEM solve of `mesh`
/// (E = 3 kPa, ν = 0.45, vertices matching `fix` fixed; a pre-computed table
/// by sparse Cholesky, Cotin 1999 §3): each held vertex `(v, u, s)` imposed
/// at `u` (m), and the result `Σ s (−g_v)`, `g_v` the force on vertex `v`,
/// N: the work-conjugate a dynamic contact with shares `s` sends.
pub fn static_reaction(
    mesh: &palpate::mesh::TetMesh,
    fix: &str,
    held: &[(u32, nalgebra::Vector3<f64>, f64)],
) -> nalgebra::Vector3<f64> {
    use palpate::table::build::{BuildOptions, build};
    use palpate_kernel::{Constraint, PrecomputedModel, PrecomputedTable};
    let options = BuildOptions::precomputed(
        palpate::fem::material::Material::new(3000.0, 0.45).expect("material"),
        vec![fix.parse().expect("predicate")],
        palpate::table::compliance::Solver::Cholesky,
        palpate::table::file::Precision::F64,
    );
    let built = build(mesh, &palpate::mesh::MeshReport::default(), &options).expect("table");
    let bytes = palpate::table::load::TableFile::from_bytes(&built.bytes);
    let table = PrecomputedTable::<f64>::load(bytes.bytes()).expect("load");
    // A vertex two contacts hold is one constraint with both shares.
    let mut merged: Vec<(u32, nalgebra::Vector3<f64>, f64)> = Vec::new();
    for &(v, u, s) in held {
        match merged.iter_mut().find(|(w, _, _)| *w == v) {
            Some((_, _, total)) => *total += s,
            None => merged.push((v, u, s)),
        }
    }
    let held = &merged;
    let contacts: Vec<Constraint<f64>> = held
        .iter()
        .map(|&(v, u, _)| Constraint::at_vertex(v, u))
        .collect();
    let solution = PrecomputedModel::new(table)
        .contact_forces::<8>(&contacts)
        .expect("static solve");
    solution
        .contact_forces_n()
        .iter()
        .zip(held)
        .map(|(g, (_, _, s))| -g * *s)
        .sum()
}

/// Mesh, fix and material: a valid pre-computed scene ending inside
/// `[material]`, 5 lines, without tool, cutting or tearing keys.
pub const BASE_SCENE: &str =
    "mesh = \"a.msh\"\nfix = [\"z<0.001\"]\n[material]\nyoung_pa = 3000\npoisson = 0.45\n";

/// The scene of TOML `text` named `scene.toml` in the folder `/scenes`;
/// panics with the error's message if it does not validate.
pub fn scene(text: &str) -> Scene {
    match Scene::from_toml_str_named(text, "scene.toml", Path::new("/scenes")) {
        Ok(s) => s,
        Err(e) => panic!("{e}"),
    }
}

/// The error message of the scene of TOML `text` named `bad.toml` in the
/// folder `/scenes`; panics if it validates.
pub fn scene_err(text: &str) -> String {
    match Scene::from_toml_str_named(text, "bad.toml", Path::new("/scenes")) {
        Ok(s) => panic!("expected an error, got {s:?}"),
        Err(e) => e.to_string(),
    }
}

/// Each `(text, expected)` of `cases`: the scene of TOML `text` is refused
/// ([`scene_err`]) with exactly the one-line message `expected`.
pub fn assert_scene_errors(cases: &[(String, &str)]) {
    for (text, expected) in cases {
        let msg = scene_err(text);
        assert!(
            msg == *expected,
            "\n   got: {msg}\nwanted: {expected}\n  text:\n{text}"
        );
        assert!(!msg.contains('\n'), "one line: {msg}");
    }
}

/// The trajectory of CSV `text` named `traj.csv` for `tools` tool points;
/// panics with the error's message if it is refused.
pub fn traj(text: &str, tools: usize) -> Trajectory {
    match Trajectory::from_csv_str(text, "traj.csv", tools) {
        Ok(t) => t,
        Err(e) => panic!("{e}"),
    }
}

/// The error message of the trajectory of CSV `text` named `traj.csv` for
/// `tools` tool points; panics if it is read.
pub fn traj_err(text: &str, tools: usize) -> String {
    match Trajectory::from_csv_str(text, "traj.csv", tools) {
        Ok(t) => panic!("expected an error, got {} samples", t.samples().len()),
        Err(e) => e.to_string(),
    }
}

/// The trajectory file `t` writes (`Trajectory::write_csv`), as text.
pub fn csv(t: &Trajectory) -> String {
    let mut bytes = Vec::new();
    t.write_csv(&mut bytes).expect("write to memory");
    String::from_utf8(bytes).expect("UTF-8")
}

/// A trajectory tool point's state: at `position_m` with the jaw opening
/// `jaw_m`, the blade enabled if `cut`.
pub fn tool_state(position_m: [f64; 3], jaw_m: f64, cut: bool) -> ToolState {
    ToolState {
        position_m,
        jaw_m,
        cut,
    }
}

/// The first keyframe of tool point `tool` labelled `label`; panics if there
/// is none.
pub fn keyframe(keys: &[Keyframe], tool: usize, label: &str) -> Keyframe {
    *keys
        .iter()
        .find(|k| k.tool == tool && k.label == label)
        .unwrap_or_else(|| panic!("no {label} keyframe for tool {tool}"))
}

/// A haptic loop configuration (f64) that never clamps: tool spheres of
/// `radius_m` (m), ticks of `tick_s` (s), force and slew limits of 1e3 N and
/// 1e9 N/s, so a test sees the tissue's own force.
pub fn unclamped_loop_config(
    radius_m: f64,
    tick_s: f64,
) -> palpate_kernel::haptic::LoopConfig<f64> {
    palpate_kernel::haptic::LoopConfig {
        radius_m,
        dt_s: tick_s,
        limits: palpate_kernel::haptic::SafetyLimits {
            max_force_n: 1e3,
            max_slew_n_per_s: 1e9,
        },
    }
}

/// The largest difference between `model`'s current vertex and edge tensors
/// (its table in `file`, edges in that table's CSR order) and the tensors of
/// `rebuilt` (a mesh's arrays assembled afresh; an edge it lacks counts as
/// zero), and the largest entry of `rebuilt`'s vertex tensors, N/m: a local
/// removal checked against a rebuild without the removed tets.
pub fn tensor_difference(
    model: &palpate_kernel::tensor_mass::TensorMassModel<'_, '_, f64>,
    file: &palpate::table::load::TableFile,
    rebuilt: &palpate::table::tensor_mass::TensorMassArrays,
) -> (f64, f64) {
    let scale = rebuilt
        .vertex_tensors
        .iter()
        .flatten()
        .fold(0.0f64, |m, x| m.max(x.abs()));
    let mut worst = 0.0f64;
    for (ours, theirs) in model.vertex_tensors().iter().zip(&rebuilt.vertex_tensors) {
        for (a, b) in ours.iter().zip(theirs) {
            worst = worst.max((a - b).abs());
        }
    }
    // Edges: look each original edge up in the rebuilt CSR (absent = zero).
    let table =
        palpate_kernel::table::TensorMassTable::<f64>::load(file.bytes()).expect("valid table");
    let rows = table.edge_row_starts();
    for i in 0..table.vertex_count() {
        for e in rows[i] as usize..rows[i + 1] as usize {
            let j = table.edge_columns()[e];
            let start = rebuilt.row_start[i] as usize;
            let row = &rebuilt.column[start..rebuilt.row_start[i + 1] as usize];
            let want = row
                .binary_search(&j)
                .map_or([0.0; 9], |k| rebuilt.edge_tensors[start + k]);
            let ours = model
                .edge_tensor(i as u32, j)
                .expect("every edge is stored");
            for (a, b) in ours.iter().zip(&want) {
                worst = worst.max((a - b).abs());
            }
        }
    }
    (worst, scale)
}

/// The f32 tables of the firmware example's box (`tools/firmware-m4f/mesh/box.*`: 3 × 3 × 3
/// cells of 1 cm, 64 vertices, 162 tets, base fixed, E = 3 kPa, ν = 0.45), built in memory
/// exactly as `tools/box-table.sh` (pre-computed; tensor-mass with ρ = 1000 kg/m³) and
/// `tools/hybrid-tables.sh` (the hybrid of `hybrid-scene.toml`: the top corner cell
/// tensor-mass) build them: what the C ABI's tests load.
pub struct FirmwareBoxTables {
    /// The pre-computed table.
    pub precomputed: palpate::table::load::TableFile,
    /// The tensor-mass table.
    pub tensor_mass: palpate::table::load::TableFile,
    /// The hybrid's three tables.
    pub hybrid: palpate::hybrid::HybridTables,
}

/// [`FirmwareBoxTables`], built once per test binary.
pub fn firmware_box_tables() -> &'static FirmwareBoxTables {
    use palpate::fem::material::Material;
    use palpate::session::model::{SceneModel, hybrid_tables};
    use palpate::table::build::{BuildOptions, build};
    use palpate::table::compliance::Solver;
    use palpate::table::file::Precision;
    use palpate::table::load::TableFile;

    static TABLES: std::sync::OnceLock<FirmwareBoxTables> = std::sync::OnceLock::new();
    TABLES.get_or_init(|| {
        let firmware = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../tools/firmware-m4f");
        let (mesh, report) =
            palpate::mesh::read_mesh(&firmware.join("mesh/box.node")).expect("box mesh");
        let material = Material::new(3000.0, 0.45).expect("material");
        let fix = vec!["z<0.001".parse().expect("predicate")];
        let table = |options: BuildOptions| {
            TableFile::from_bytes(&build(&mesh, &report, &options).expect("table").bytes)
        };
        let scene = Scene::read(&firmware.join("hybrid-scene.toml")).expect("hybrid scene");
        let (scene_mesh, scene_report) = scene.load_mesh().expect("scene mesh");
        let SceneModel::Hybrid { partition, .. } =
            SceneModel::of(&scene, &scene_mesh, &scene_report).expect("scene model")
        else {
            panic!("hybrid-scene.toml is not a hybrid");
        };
        FirmwareBoxTables {
            precomputed: table(BuildOptions::precomputed(
                material,
                fix.clone(),
                Solver::Cholesky,
                Precision::F32,
            )),
            tensor_mass: table(BuildOptions::tensor_mass(
                material,
                1000.0,
                fix,
                Precision::F32,
            )),
            hybrid: hybrid_tables(
                &scene,
                &scene_mesh,
                &scene_report,
                &partition,
                Precision::F32,
            )
            .expect("hybrid tables"),
        }
    })
}

/// A pre-computed table with hand-set contents (a 5-vertex mesh, vertex 0
/// fixed), so that each structural check of the loader can be hit behind a
/// valid checksum; [`TinyTable::bytes`] writes it with the host's writer.
pub struct TinyTable {
    /// Each vertex's free index or `u32::MAX` (fixed).
    pub vertex_slot: Vec<u32>,
    /// Free index → vertex; the first `touchable_count` are touchable.
    pub free_vertex: Vec<u32>,
    /// Touchable vertices (`S`).
    pub touchable_count: usize,
    /// Rest positions, m.
    pub positions: Vec<[f64; 3]>,
    /// Boundary triangles.
    pub triangles: Vec<[u32; 3]>,
    /// Packed surface compliance blocks, m/N.
    pub surface: Vec<[f64; 9]>,
    /// Interior compliance blocks, m/N.
    pub interior: Vec<[f64; 9]>,
    /// The compliance compressed, if it is to be written so.
    pub compressed: Option<palpate::table::compress::CompressedCompliance>,
    /// Young's modulus, Pa.
    pub young_pa: f64,
}

impl TinyTable {
    /// An SPD compliance block (m/N) every block of the tiny tables holds.
    pub const SPD: [f64; 9] = [2e-4, 1e-5, 0.0, 1e-5, 3e-4, 0.0, 0.0, 0.0, 1e-4];

    /// 5 vertices, vertex 0 fixed; free 1..=4 all touchable (S = F = 4).
    pub fn new() -> Self {
        Self {
            vertex_slot: vec![u32::MAX, 0, 1, 2, 3],
            free_vertex: vec![1, 2, 3, 4],
            touchable_count: 4,
            positions: vec![
                [0.0; 3],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 1.0],
                [1.0, 1.0, 1.0],
            ],
            triangles: vec![[1, 2, 3]],
            surface: vec![Self::SPD; 10],
            interior: vec![],
            compressed: None,
            young_pa: 1000.0,
        }
    }

    /// [`TinyTable::new`] with a sixth vertex, free and interior (S = 4,
    /// F = 5): one interior block per column, the compliance falling off
    /// with the column `k` as `SPD / (k + 2)`.
    pub fn with_interior() -> Self {
        let mut t = Self::new();
        t.vertex_slot.push(4);
        t.free_vertex.push(5);
        t.positions.push([0.5, 0.5, 0.5]);
        t.interior = (0..4)
            .map(|k| Self::SPD.map(|x| x / (k as f64 + 2.0)))
            .collect();
        t
    }

    /// The table's compliance as the host computes it.
    pub fn compliance(&self) -> palpate::table::compliance::Compliance {
        palpate::table::compliance::Compliance {
            surface: self.surface.clone(),
            interior: self.interior.clone(),
        }
    }

    /// The table file (f32), compressed as [`TinyTable::compressed`] says.
    pub fn bytes(&self) -> Vec<u8> {
        self.bytes_with_index(|_| {})
    }

    /// [`Self::bytes`] with the collision index as `edit` leaves it (a
    /// corrupted section behind a valid checksum).
    pub fn bytes_with_index(
        &self,
        edit: impl FnOnce(&mut palpate::table::collision::CollisionIndex),
    ) -> Vec<u8> {
        use palpate::table::collision::collision_index;
        use palpate::table::file::{Precision, TableContents, write_table};
        let mut collision = collision_index(
            &self.positions,
            &self.triangles,
            palpate::table::build::DEFAULT_LIST_TOOL_RADIUS_M,
            Precision::F32,
        );
        edit(&mut collision);
        write_table(
            &TableContents {
                tet_lame: &[[1.0, 1.0]; 2],
                young_pa: self.young_pa,
                poisson: 0.3,
                mesh_hash: 7,
                vertex_slot: &self.vertex_slot,
                free_vertex: &self.free_vertex,
                touchable_count: self.touchable_count,
                positions: &self.positions,
                triangles: &self.triangles,
                surface: &self.surface,
                interior: &self.interior,
                compressed: self.compressed.as_ref(),
                collision: &collision,
            },
            Precision::F32,
        )
    }
}

impl Default for TinyTable {
    fn default() -> Self {
        Self::new()
    }
}

/// Where section `kind`'s payload lies in table `bytes`: byte offset,
/// element size and count, from its directory entry.
pub fn section_span(
    bytes: &[u8],
    kind: palpate_kernel::table::format::SectionKind,
) -> (usize, usize, usize) {
    use palpate_kernel::table::format::{HEADER_LEN, SECTION_ENTRY_LEN};
    let u32_at = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap());
    let u64_at = |at: usize| u64::from_le_bytes(bytes[at..at + 8].try_into().unwrap());
    // RawHeader: section_count at byte 20; SectionEntry: kind, elem_bytes, offset, count.
    let sections = u32_at(20) as usize;
    let entry = (0..sections)
        .map(|i| HEADER_LEN + i * SECTION_ENTRY_LEN)
        .find(|&at| u32_at(at) == kind as u32)
        .expect("section present");
    (
        u64_at(entry + 8) as usize,
        u32_at(entry + 4) as usize,
        u64_at(entry + 16) as usize,
    )
}

/// `bytes` with `f` applied to the payload of section `kind` and the CRC-32
/// trailer repaired (a corrupted section behind a valid checksum).
pub fn patch_section(
    bytes: &[u8],
    kind: palpate_kernel::table::format::SectionKind,
    f: impl FnOnce(&mut [u8]),
) -> Vec<u8> {
    use palpate_kernel::table::format::{CRC_LEN, CRC32};
    let mut out = bytes.to_vec();
    let (offset, elem, count) = section_span(&out, kind);
    f(&mut out[offset..offset + elem * count]);
    let body = out.len() - CRC_LEN;
    let crc = crc::Crc::<u32>::new(&CRC32).checksum(&out[..body]);
    out[body..].copy_from_slice(&crc.to_le_bytes());
    out
}

/// A deterministic pseudo-random stream (a 64-bit LCG with Knuth's MMIX
/// constants): no test depends on a random crate's stream.
pub struct Lcg(pub u64);

impl Lcg {
    /// The next number, uniform in `[0, 1)` (the state's top 53 bits).
    pub fn unit(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }

    /// The next number, uniform in `[−1, 1)`.
    pub fn signed(&mut self) -> f64 {
        2.0 * self.unit() - 1.0
    }
}

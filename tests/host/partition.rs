//! The hybrid partition planner (`host-harness/src/partition/`) against hand counts on the
//! generated Kuhn box (6 tets per cell, `box_mesh`), brute-force counts of connection nodes and
//! ring growth, and the measurement behind the default margin (`DEFAULT_MARGIN_RINGS`): how far
//! from a pulled cut the static deformation stays past the linear model's range.

use palpate::fem::element::shape_gradients;
use palpate::fem::material::{Material, TetMaterials};
use palpate::fem::static_solve::solve_prescribed;
use palpate::mesh::TetMesh;
use palpate::mesh::generate::box_mesh;
use palpate::partition::{Partition, PlanError, PlanInput, RegionModel, plan};
use palpate::scene::zones::DEFAULT_MARGIN_RINGS;
use palpate::scene::{GraspPull, Zone, ZoneKind, ZoneShape};
use palpate_kernel::tensor_mass::ElasticLaw;

/// A 4 × 4 × 4-cell box of 1 cm cells (384 tets, 125 vertices).
fn block() -> TetMesh {
    box_mesh([4, 4, 4], [0.04; 3])
}

/// The base `z = 0` fixed.
fn base_fixed(mesh: &TetMesh) -> Vec<bool> {
    mesh.positions.iter().map(|p| p[2] < 1e-9).collect()
}

fn cut(shape: ZoneShape) -> Zone {
    Zone {
        kind: ZoneKind::Cut,
        shape,
    }
}

fn planned(
    mesh: &TetMesh,
    zones: &[Zone],
    rings: u32,
    poisson: f64,
) -> Result<Partition, PlanError> {
    let fixed = base_fixed(mesh);
    plan(&PlanInput {
        mesh,
        fixed: &fixed,
        zones,
        margin_rings: rings,
        poisson,
        scene: "scene.toml",
        mesh_name: "block",
    })
}

fn dynamic_count(p: &Partition) -> usize {
    p.dynamic.iter().filter(|&&d| d).count()
}

/// Connection nodes by brute force: vertices of some dynamic and some pre-computed tet.
fn brute_connection_nodes(mesh: &TetMesh, dynamic: &[bool]) -> Vec<u32> {
    (0..mesh.positions.len() as u32)
        .filter(|&v| {
            let uses = |d: bool| {
                mesh.tets
                    .iter()
                    .zip(dynamic)
                    .any(|(t, &dt)| dt == d && t.contains(&v))
            };
            uses(true) && uses(false)
        })
        .collect()
}

#[test]
fn a_box_on_the_grid_takes_its_cells_and_nothing_that_only_touches_it() {
    let mesh = block();
    // 2 × 1 × 1 cells: 12 tets; the neighbours sharing its faces are not taken.
    let zones = [cut(ZoneShape::Box {
        min_m: [0.01, 0.01, 0.03],
        max_m: [0.03, 0.02, 0.04],
    })];
    let p = planned(&mesh, &zones, 0, 0.3).unwrap();
    assert_eq!(dynamic_count(&p), 12);
    assert_eq!(
        p.connection_nodes,
        brute_connection_nodes(&mesh, &p.dynamic)
    );
    // The 2 × 1 × 1 block's 12 vertices are all shared with pre-computed tets.
    assert_eq!(p.connection_nodes.len(), 12);
    // A box inside one cell takes the tets of that cell it meets: all 6 share the cell's
    // main diagonal, which a box around the cell centre contains.
    let zones = [cut(ZoneShape::Box {
        min_m: [0.014, 0.014, 0.014],
        max_m: [0.016, 0.016, 0.016],
    })];
    assert_eq!(dynamic_count(&planned(&mesh, &zones, 0, 0.3).unwrap()), 6);
}

#[test]
fn a_sphere_at_a_vertex_takes_the_tets_around_it() {
    let mesh = block();
    // Interior vertex (0.02, 0.02, 0.02): in a Kuhn grid, 24 tets use an interior vertex.
    let around = |r: f64| {
        let zones = [cut(ZoneShape::Sphere {
            center_m: [0.02; 3],
            radius_m: r,
        })];
        dynamic_count(&planned(&mesh, &zones, 0, 0.3).unwrap())
    };
    assert_eq!(around(0.001), 24);
    let v = mesh.positions.iter().position(|p| *p == [0.02; 3]).unwrap() as u32;
    assert_eq!(mesh.tets.iter().filter(|t| t.contains(&v)).count(), 24);
    // A sphere of one cell's half diagonal and more takes more.
    assert!(around(0.009) > 24);
}

#[test]
fn a_capsule_and_a_path_along_a_grid_line_take_the_same_tets() {
    let mesh = block();
    // The vertical grid line x = y = 0.02 through the block, radius 1 mm: the 72 tets with a
    // vertex on it (any other tet of the cells around it is at least 7 mm away).
    let capsule = [cut(ZoneShape::Capsule {
        a_m: [0.02, 0.02, -0.01],
        b_m: [0.02, 0.02, 0.05],
        radius_m: 0.001,
    })];
    let p = planned(&mesh, &capsule, 0, 0.3).unwrap();
    let on_line = |t: &[u32; 4]| {
        t.iter().any(|&v| {
            let q = mesh.positions[v as usize];
            (q[0] - 0.02).abs() < 1e-12 && (q[1] - 0.02).abs() < 1e-12
        })
    };
    let expected = mesh.tets.iter().filter(|t| on_line(t)).count();
    assert_eq!((dynamic_count(&p), expected), (72, 72));
    let path = [cut(ZoneShape::Path {
        trajectory: "line.csv".into(),
        polylines: vec![vec![
            [0.02, 0.02, -0.01],
            [0.02, 0.02, 0.02],
            [0.02, 0.02, 0.05],
        ]],
        radius_m: 0.001,
    })];
    assert_eq!(planned(&mesh, &path, 0, 0.3).unwrap().dynamic, p.dynamic);
}

#[test]
fn margin_rings_grow_by_one_vertex_neighbourhood_each() {
    let mesh = block();
    let zones = [cut(ZoneShape::Box {
        min_m: [0.01, 0.01, 0.03],
        max_m: [0.02, 0.02, 0.04],
    })];
    let mut previous = planned(&mesh, &zones, 0, 0.3).unwrap().dynamic;
    assert_eq!(previous.iter().filter(|&&d| d).count(), 6);
    for k in 1..=3 {
        let now = planned(&mesh, &zones, k, 0.3).unwrap().dynamic;
        // Brute force: the previous set plus every tet sharing a vertex with it.
        let verts: Vec<u32> = mesh
            .tets
            .iter()
            .zip(&previous)
            .filter(|(_, d)| **d)
            .flat_map(|(t, _)| *t)
            .collect();
        let expected: Vec<bool> = mesh
            .tets
            .iter()
            .zip(&previous)
            .map(|(t, &d)| d || t.iter().any(|v| verts.contains(v)))
            .collect();
        assert_eq!(now, expected, "ring {k}");
        previous = now;
    }
}

#[test]
fn the_law_follows_the_zones_and_the_poisson_ratio() {
    let mesh = block();
    let cut_zone = cut(ZoneShape::Box {
        min_m: [0.0, 0.0, 0.03],
        max_m: [0.01, 0.01, 0.04],
    });
    let large = Zone {
        kind: ZoneKind::LargeDeformation,
        shape: ZoneShape::Box {
            min_m: [0.03, 0.03, 0.03],
            max_m: [0.04, 0.04, 0.04],
        },
    };
    let p = planned(&mesh, &[cut_zone.clone(), large.clone()], 0, 0.45).unwrap();
    let models: Vec<RegionModel> = p.regions.iter().map(|r| r.model).collect();
    assert_eq!(models.len(), 3);
    assert_eq!(models[0], RegionModel::Precomputed);
    assert_eq!(
        models[1],
        RegionModel::TensorMass {
            law: ElasticLaw::Linear,
            incompressibility: false
        }
    );
    assert!(matches!(
        models[2],
        RegionModel::TensorMass {
            law: ElasticLaw::StVenantKirchhoff(_),
            incompressibility: true
        }
    ));
    assert!(
        p.regions[2].why.contains("large-deformation"),
        "{}",
        p.regions[2].why
    );
    // Below ν = 0.45 no penalty.
    let p = planned(&mesh, &[large], 0, 0.3).unwrap();
    assert_eq!(p.regions[1].model.law_name(), "stvk");
}

#[test]
fn no_zone_is_all_precomputed_and_the_whole_organ_cut_is_all_tensor_mass() {
    let mesh = block();
    let p = planned(&mesh, &[], 2, 0.45).unwrap();
    assert_eq!(p.regions.len(), 1);
    assert_eq!(p.regions[0].model, RegionModel::Precomputed);
    assert_eq!(p.regions[0].tets.len(), mesh.tets.len());
    assert!(p.connection_nodes.is_empty());
    assert!(p.regions[0].why.contains("no [[zone]]"));
    let all = [cut(ZoneShape::Box {
        min_m: [-1.0; 3],
        max_m: [1.0; 3],
    })];
    let p = planned(&mesh, &all, 2, 0.45).unwrap();
    assert_eq!(p.regions.len(), 1);
    assert_eq!(p.regions[0].model.name(), "tensor-mass");
    assert_eq!(p.regions[0].tets.len(), mesh.tets.len());
    assert!(p.connection_nodes.is_empty());
    assert_eq!(p.region_of_tets(), vec![1; mesh.tets.len()]);
}

#[test]
fn bad_partitions_are_refused_naming_the_zone_or_region() {
    let mesh = block();
    let outside = [cut(ZoneShape::Sphere {
        center_m: [1.0; 3],
        radius_m: 0.01,
    })];
    assert_eq!(
        planned(&mesh, &outside, 2, 0.45).unwrap_err().to_string(),
        "scene.toml: [[zone]] 1 (cut, sphere) contains no tet of mesh block"
    );
    // The whole block dynamic with nothing fixed floats.
    let all = [cut(ZoneShape::Box {
        min_m: [-1.0; 3],
        max_m: [1.0; 3],
    })];
    let err = plan(&PlanInput {
        mesh: &mesh,
        fixed: &vec![false; mesh.positions.len()],
        zones: &all,
        margin_rings: 0,
        poisson: 0.3,
        scene: "scene.toml",
        mesh_name: "block",
    })
    .unwrap_err()
    .to_string();
    assert!(
        err.starts_with("scene.toml: dynamic region 1 (384 tets"),
        "{err}"
    );
    assert!(err.contains("it floats") && !err.contains('\n'), "{err}");
    // A slab across the block (it meets the cell layers z in [0.01, 0.03]) splits the
    // pre-computed region in two pieces; the top one is held by its connection nodes only:
    // accepted, and reported.
    let slab = [cut(ZoneShape::Box {
        min_m: [-1.0, -1.0, 0.015],
        max_m: [1.0, 1.0, 0.025],
    })];
    let p = planned(&mesh, &slab, 0, 0.3).unwrap();
    assert_eq!(p.regions[0].pieces, 2);
    assert!(p.regions[0].why.contains("2 pieces"));
    // Two separate blocks, only the first one's base fixed: the second block floats.
    let mut two = block();
    let shifted = box_mesh([4, 4, 4], [0.04; 3]);
    let offset = two.positions.len() as u32;
    two.positions.extend(
        shifted
            .positions
            .iter()
            .map(|p| [p[0] + 0.1, p[1], p[2] + 0.01]),
    );
    two.tets
        .extend(shifted.tets.iter().map(|t| t.map(|v| v + offset)));
    let err = planned(&two, &[], 0, 0.3).unwrap_err().to_string();
    assert!(
        err.starts_with("scene.toml: piece 2 of 2 of the pre-computed region (384 tets"),
        "{err}"
    );
}

/// The margin default's measurement (README "scene plan"): on the demo block (12 × 12 × 6 cells
/// of 1 cm, base fixed, E = 3 kPa, ν = 0.45), cut a 4 cm slit (1 × 4 × 3 cells at the top
/// centre: 72 tets) and pull its lip sideways by the built-in grasp-pull's 8 mm
/// (`GraspPull::default().pull_m`); solve the linear static problem of the cut mesh. The
/// pre-computed model is valid for small deformation (about 10 % of the object's size,
/// MODELS.md §2): the margin must reach where the displacement gradient `|∇u|` (Frobenius, per
/// tet) falls below 0.1. Outside the slit plus `k` rings the largest `|∇u|` is 0.73, 0.36,
/// 0.20, 0.127, 0.097 for `k` = 0..=4: below 0.1 first at `k = DEFAULT_MARGIN_RINGS` = 4.
#[test]
fn margin_default_is_where_a_pulled_cut_is_back_in_the_linear_range() {
    let mesh = box_mesh([12, 12, 6], [0.12, 0.12, 0.06]);
    let material = Material::new(3000.0, 0.45).unwrap();
    let slit = [cut(ZoneShape::Box {
        min_m: [0.05, 0.04, 0.03],
        max_m: [0.06, 0.08, 0.06],
    })];
    let cut_tets = planned(&mesh, &slit, 0, 0.45).unwrap().dynamic;
    assert_eq!(cut_tets.iter().filter(|&&d| d).count(), 72);
    let lip = mesh
        .positions
        .iter()
        .position(|p| (p[0] - 0.05).abs() < 1e-9 && (p[1] - 0.06).abs() < 1e-9 && p[2] > 0.0599)
        .unwrap() as u32;
    let pull = [(lip, [-GraspPull::default().pull_m, 0.0, 0.0])];
    let kept: Vec<[u32; 4]> = mesh
        .tets
        .iter()
        .zip(&cut_tets)
        .filter(|(_, c)| !**c)
        .map(|(t, _)| *t)
        .collect();
    let mut used = vec![false; mesh.positions.len()];
    kept.iter().flatten().for_each(|&v| used[v as usize] = true);
    let fixed: Vec<bool> = base_fixed(&mesh)
        .iter()
        .zip(&used)
        .map(|(f, u)| *f || !u)
        .collect();
    let (u, _) = solve_prescribed(
        &mesh.positions,
        &kept,
        &TetMaterials::uniform(material, kept.len()),
        &fixed,
        &pull,
    )
    .unwrap();
    // |∇u| of tet t: ∇u = Σ_j u_j ⊗ a_j (MODELS.md §1).
    let gradient = |t: &[u32; 4]| {
        let (a, _) = shape_gradients(&t.map(|v| mesh.positions[v as usize]));
        let mut g = [[0.0f64; 3]; 3];
        for (j, &v) in t.iter().enumerate() {
            for (r, row) in g.iter_mut().enumerate() {
                for (c, x) in row.iter_mut().enumerate() {
                    *x += u[v as usize][r] * a[j][c];
                }
            }
        }
        g.iter().flatten().map(|x| x * x).sum::<f64>().sqrt()
    };
    let outside = |k: u32| {
        let p = planned(&mesh, &slit, k, 0.45).unwrap();
        mesh.tets
            .iter()
            .zip(&p.dynamic)
            .filter(|(_, d)| !**d)
            .map(|(t, _)| gradient(t))
            .fold(0.0, f64::max)
    };
    let largest: Vec<f64> = (0..=DEFAULT_MARGIN_RINGS).map(outside).collect();
    eprintln!(
        "largest |grad u| outside the slit + k rings, k = 0..={DEFAULT_MARGIN_RINGS}: {largest:.4?}"
    );
    let first_below = largest.iter().position(|&g| g < 0.1);
    assert_eq!(
        first_below,
        Some(DEFAULT_MARGIN_RINGS as usize),
        "{largest:?}"
    );
}

/// No pre-computed boundary face has three connection nodes (held in the pre-computed region's
/// table: it could answer no contact there). On the built-in organ under the built-in hybrid
/// scene's cut zone, margin rings 1–4 left such faces before the planner moved their tets into
/// the tensor-mass region; the count is exact (every face is checked).
#[test]
fn no_precomputed_boundary_face_is_all_connection_nodes_on_the_organ() {
    use palpate::mesh::{boundary_face_slots, organ::organ};
    use palpate::scene::Scene;
    use palpate_kernel::table::format::tet_face_vertices;

    let (mesh, report) = organ().unwrap();
    let boundary = boundary_face_slots(&mesh);
    let mut scene = Scene::built_in_hybrid();
    for rings in 0..=4 {
        scene.partition.margin_rings = rings;
        let p = Partition::of_scene(&scene, &mesh, &report).unwrap();
        let connection = brute_connection_nodes(&mesh, &p.dynamic);
        let whole = (0..mesh.tets.len())
            .filter(|&t| !p.dynamic[t])
            .flat_map(|t| {
                let faces = tet_face_vertices(mesh.tets[t]);
                (0..4).map(move |j| (t, j, faces[j]))
            })
            .filter(|&(t, j, face)| {
                boundary[4 * t + j] && face.iter().all(|v| connection.binary_search(v).is_ok())
            })
            .count();
        assert_eq!(
            whole, 0,
            "margin rings {rings}: all-connection boundary faces"
        );
        assert_eq!(p.connection_nodes, connection, "margin rings {rings}");
    }
}

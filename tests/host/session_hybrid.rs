//! Sessions on scenes with `[[zone]]`s (`palpate::session::model`): the
//! zones' partition chooses the model. The built-in hybrid scene cuts only
//! its tensor-mass region while its grasper holds the pre-computed one; a
//! zone over the whole mesh runs the tensor-mass model exactly as the
//! scene without zones; zones that make tets dynamic need the dynamic
//! model's step.

use palpate::partition::Partition;
use palpate::scene::generate::hepatectomy;
use palpate::scene::{Generator, PressHold, Scene};
use palpate::session::run::{SessionOutputs, run_session, run_session_into};
use palpate_tests::scene;

/// `built-in-hybrid` over `session generate hepatectomy`: the cuts and
/// tears remove tets of the tensor-mass region only (the partition's
/// dynamic tets), at least the 10 along the cut line (measured 344), and
/// cut the left lobe through (its tip has no face path of live tets to the
/// right lobe); the grasp holds the pre-computed region and pulls the hand
/// (the force's magnitude above 0.5 N while held, measured 0.91 N); no
/// fault, no failed physics update.
#[test]
fn built_in_hybrid_cuts_its_tensor_mass_region_and_grasps_its_precomputed_one() {
    let scene = Scene::named("built-in-hybrid").expect("built-in");
    let trajectory = hepatectomy(&scene.tool).expect("trajectory");
    let (mesh, report) = scene.load_mesh().expect("organ");
    let partition = Partition::of_scene(&scene, &mesh, &report).expect("partition");
    let dynamic = partition.dynamic.iter().filter(|&&d| d).count();
    assert!(
        dynamic > 0 && dynamic < mesh.tets.len(),
        "a hybrid: {dynamic} dynamic tets"
    );
    let (mut csv, mut removed) = (Vec::new(), Vec::new());
    let summary = run_session_into(
        &scene,
        &trajectory,
        SessionOutputs {
            csv: &mut csv,
            removed: Some(&mut removed),
            vtk_dir: None,
            vtk_name: None,
        },
    )
    .expect("session");
    assert_eq!(summary.faulted, 0);
    assert!(
        summary.physics_error.is_none(),
        "{:?}",
        summary.physics_error
    );
    let removed: Vec<u32> = String::from_utf8(removed)
        .expect("utf-8")
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(1).expect("tet").parse().expect("index"))
        .collect();
    println!(
        "built-in-hybrid: {dynamic} of {} tets dynamic, {} connection nodes, {} tets removed, max force {:.3} N",
        mesh.tets.len(),
        partition.connection_nodes.len(),
        removed.len(),
        summary.max_force_n
    );
    assert!(removed.len() >= 10, "{} removed", removed.len());
    // No pre-computed boundary triangle of the organ's surface has only
    // connection nodes (a contact there would be refused: its vertices are
    // all held in the pre-computed table): the partition leaves none.
    let surface = palpate::mesh::boundary_surface(&mesh);
    let mut owner = std::collections::HashMap::new();
    for (t, tet) in mesh.tets.iter().enumerate() {
        for face in palpate_kernel::table::format::tet_face_vertices(*tet) {
            let mut key = face;
            key.sort_unstable();
            owner.insert(key, t);
        }
    }
    let connects = |v: u32| partition.connection_nodes.binary_search(&v).is_ok();
    let held_only = surface
        .triangles
        .iter()
        .filter(|tri| {
            let mut key = **tri;
            key.sort_unstable();
            !partition.dynamic[owner[&key]] && tri.iter().all(|&v| connects(v))
        })
        .count();
    assert_eq!(held_only, 0);
    assert!(removed.iter().all(|&t| partition.dynamic[t as usize]));
    assert!(summary.max_force_n > 0.5);
    // The cut goes through: the live tets leave the left lobe's tip (the tet furthest in −x)
    // with no face path to the right lobe (the tet furthest in +x).
    let mut alive = vec![true; mesh.tets.len()];
    for &t in &removed {
        alive[t as usize] = false;
    }
    let by_x = |t: &usize| mesh.tet_centroid(*t)[0];
    let tip = (0..mesh.tets.len()).min_by(|a, b| by_x(a).total_cmp(&by_x(b)));
    let right = (0..mesh.tets.len()).max_by(|a, b| by_x(a).total_cmp(&by_x(b)));
    let (tip, right) = (tip.expect("tets"), right.expect("tets"));
    assert!(alive[tip] && alive[right]);
    assert!(!face_connected(&mesh.tets, &alive, tip, right));
}

/// Whether a path of face-sharing `alive` tets joins tet `from` to tet `to`.
fn face_connected(tets: &[[u32; 4]], alive: &[bool], from: usize, to: usize) -> bool {
    let mut by_face: std::collections::HashMap<[u32; 3], Vec<usize>> = Default::default();
    for (t, tet) in tets.iter().enumerate().filter(|(t, _)| alive[*t]) {
        for face in palpate_kernel::table::format::tet_face_vertices(*tet) {
            let mut key = face;
            key.sort_unstable();
            by_face.entry(key).or_default().push(t);
        }
    }
    let (mut seen, mut stack) = (vec![false; tets.len()], vec![from]);
    seen[from] = true;
    while let Some(t) = stack.pop() {
        for face in palpate_kernel::table::format::tet_face_vertices(tets[t]) {
            let mut key = face;
            key.sort_unstable();
            for &n in &by_face[&key] {
                if !seen[n] {
                    seen[n] = true;
                    stack.push(n);
                }
            }
        }
    }
    seen[to]
}

/// A zone over the whole block makes every tet dynamic: the session is
/// the tensor-mass model's, byte for byte the scene without the zone.
#[test]
fn a_zone_over_the_whole_mesh_is_the_tensor_mass_model() {
    let base = "fix = [\"z<0.0001\"]\n[generated]\nbox_m = [0.04, 0.04, 0.02]\ncells = [4, 4, 2]\n[material]\nyoung_pa = 3000.0\npoisson = 0.3\n[model]\nkind = \"dynamic\"\ndt_s = 0.0005\ndamping_per_s = 30.0\n[rates]\nphysics_every = 10\n";
    let zone = "[[zone]]\nkind = \"cut\"\nshape = \"box\"\nmin_m = [-1.0, -1.0, -1.0]\nmax_m = [1.0, 1.0, 1.0]\n";
    let press = PressHold {
        press: palpate::scene::Press {
            surface_m: [0.02, 0.02, 0.02],
            ..PressHold::default().press
        },
        ..PressHold::default()
    }
    .trajectory()
    .expect("trajectory");
    let run = |text: &str| {
        let mut out = Vec::new();
        run_session(&scene(text), &press, &mut out, None).expect("session");
        out
    };
    let plain = run(base);
    assert_eq!(run(&format!("{base}{zone}")), plain);
    assert!(String::from_utf8(plain).expect("utf-8").lines().count() > 100);
}

/// Zones that make tets dynamic on a scene whose `[model]` is pre-computed:
/// one line naming the scene and what to give.
#[test]
fn zones_with_dynamic_tets_need_the_dynamic_step() {
    let text = "fix = [\"z<0.0001\"]\n[generated]\nbox_m = [0.04, 0.04, 0.02]\ncells = [4, 4, 2]\n[material]\nyoung_pa = 3000.0\npoisson = 0.3\n[[zone]]\nkind = \"cut\"\nshape = \"sphere\"\ncenter_m = [0.02, 0.02, 0.02]\nradius_m = 0.005\n";
    let trajectory = PressHold::default().trajectory().expect("trajectory");
    let err = run_session(&scene(text), &trajectory, &mut Vec::new(), None)
        .expect_err("refused")
        .to_string();
    assert!(
        err.contains("scene.toml: the zones make") && err.contains("[model] (kind = \"dynamic\""),
        "{err}"
    );
    assert!(!err.contains('\n'), "{err}");
}

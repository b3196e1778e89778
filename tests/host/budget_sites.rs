//! The budget's probe sites (`host-harness/src/budget/sites.rs`): on the built-in block the
//! documented sites (top-face centre, y = 6, 8, 4, 10 cm: the recorded ticks of
//! `tools/cycles-check.sh` and docs/cycles.md's figures depend on them); on the built-in organ
//! (`tools/cycles-m4f/organ.toml`, its table hmatrix-q16) sites on its own surface where four
//! probes make four simultaneous contacts, counted by the kernel's haptic loop.

use std::path::Path;

use palpate::budget::{M4F_CYCLES, ProbeSites, budget_table, chosen_trajectories, probe};
use palpate::scene::{DEFAULT_TOOL_RADIUS_M, Scene, ToolSpec};

#[test]
fn the_block_keeps_its_probe_sites() {
    let sites = ProbeSites::of(&Scene::built_in()).expect("sites");
    assert_eq!(sites.anchor.surface_m, [0.06, 0.06, 0.06]);
    for (k, y_cm) in [6.0, 8.0, 4.0, 10.0].into_iter().enumerate() {
        let p = sites.points[k];
        // The same arithmetic as the sites had before they were read from the scene's mesh:
        // 6 cm plus the step times 2 cm; within an ulp of the documented y.
        assert_eq!(p.surface_m, [0.06, 0.06 + (y_cm - 6.0) / 2.0 * 0.02, 0.06]);
        assert!((p.surface_m[1] - y_cm / 100.0).abs() < 1e-15, "{k}");
        assert_eq!(p.normal, [0.0, 0.0, 1.0]);
    }
}

/// Four probes on the organ's sites, held pressed (the press-hold): the loop reports four
/// contacts at once, and every site lies on the organ (inside its 0.169 × 0.120 m footprint,
/// between its floor z = −0.02 m and its top z = 0.041 m).
#[test]
fn four_probes_make_four_contacts_on_the_organ() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tools/cycles-m4f/organ.toml");
    let mut scene = Scene::read(&path).expect("organ.toml");
    scene.tool = ToolSpec::probes(4, DEFAULT_TOOL_RADIUS_M);
    let sites = ProbeSites::of(&scene).expect("sites");
    for p in sites.points {
        let [x, y, z] = p.surface_m;
        assert!(
            x.abs() < 0.085 && y.abs() < 0.06 && (-0.02..0.041).contains(&z),
            "{p:?}"
        );
    }
    let (mesh, report) = scene.load_mesh().expect("mesh");
    let (tables, _) = budget_table(&scene, &mesh, &report, &M4F_CYCLES, None).expect("tables");
    let (_, trajectory) = chosen_trajectories(&scene, &["press-hold".into()])
        .expect("trajectories")
        .remove(0);
    let run = probe(&tables, &scene, &trajectory).expect("probe");
    let most = run.outputs.iter().map(|o| o.contacts).max();
    assert_eq!(most, Some(4));
}

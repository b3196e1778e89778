//! `palpate dynamic run|critical-dt --scene` (README "Command line"): a
//! scene in place of the mesh and material flags. On a scene whose zones
//! make part of the mesh dynamic it runs the hybrid: the JSON has every
//! mesh vertex, and its settled state under gravity and a point load on
//! each region is the one of the same scene without zones (all
//! tensor-mass: both are the global linear solution at rest, MODELS.md §5);
//! `critical-dt` prints the hybrid's step next to its region alone's.

use crate::common::{fresh_dir, palpate};

/// A 4 × 4 × 2-cell block of 1 cm (75 vertices, 192 tets), base fixed.
const BLOCK: &str = "fix = [\"z<0.0001\"]\n[generated]\nbox_m = [0.04, 0.04, 0.02]\ncells = [4, 4, 2]\n[material]\nyoung_pa = 5000.0\npoisson = 0.3\n";
/// Its corner `x, y > 2 cm` tensor-mass.
const ZONE: &str = "[[zone]]\nkind = \"cut\"\nshape = \"box\"\nmin_m = [0.02, 0.02, 0.0]\nmax_m = [0.04, 0.04, 0.02]\n[partition]\nmargin_rings = 0\n";

fn run(scene: &std::path::Path, extra: &[&str]) -> serde_json::Value {
    let mut args = vec!["dynamic", "run", "--scene", scene.to_str().unwrap()];
    args.extend_from_slice(extra);
    args.extend_from_slice(&["--json"]);
    let out = palpate(&args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn a_hybrid_scene_settles_to_the_all_tensor_mass_state() {
    let dir = fresh_dir("dynamic-scene");
    let (hybrid, whole) = (dir.join("hybrid.toml"), dir.join("whole.toml"));
    std::fs::write(&hybrid, format!("{BLOCK}{ZONE}")).unwrap();
    std::fs::write(&whole, BLOCK).unwrap();
    // Vertex 54 = (4, 0, 2) cm: pre-computed; 74 = (4, 4, 2) cm: dynamic.
    let flags = [
        "--damping",
        "300",
        "--integrator",
        "symplectic",
        "--dt",
        "0.0002",
        "--steps",
        "20000",
        "--gravity",
        "0,0,-9.81",
        "--load",
        "54:0.01,0,-0.02",
        "--load",
        "74:0,0.01,-0.01",
    ];
    let (h, w) = (run(&hybrid, &flags), run(&whole, &flags));
    let field = |v: &serde_json::Value| -> Vec<f64> {
        v["displacements"]
            .as_array()
            .unwrap()
            .iter()
            .flat_map(|u| u.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()))
            .collect()
    };
    let (fh, fw) = (field(&h), field(&w));
    assert_eq!(fh.len(), 75 * 3, "every mesh vertex");
    let size = fw.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let difference = fh
        .iter()
        .zip(&fw)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    println!(
        "hybrid vs all tensor-mass, settled: {:.2e} of {size:.3e} m",
        difference / size
    );
    // Both settled to 1e-9 of the field (20 000 steps at 300/s of damping);
    // the two models' equilibria are one.
    assert!(difference <= 1e-6 * size, "{}", difference / size);
    assert!(h["fault"].is_null());

    let out = palpate(&[
        "dynamic",
        "critical-dt",
        "--scene",
        hybrid.to_str().unwrap(),
        "--damping",
        "0",
        "--integrator",
        "symplectic",
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let (coupled, alone) = (
        json["hybrid"]["critical_dt"].as_f64().unwrap(),
        json["region_alone"]["critical_dt"].as_f64().unwrap(),
    );
    println!("critical dt: hybrid {coupled:.4e} s, region alone {alone:.4e} s");
    assert!(coupled > 0.0 && coupled >= 0.9 * alone);
}

/// `--scene` replaces the mesh and its material flags: given both, one
/// line naming the conflict, exit 2.
#[test]
fn scene_and_mesh_flags_conflict() {
    let out = palpate(&[
        "dynamic",
        "run",
        "mesh.msh",
        "--scene",
        "built-in",
        "--damping",
        "1",
        "--integrator",
        "symplectic",
        "--dt",
        "0.001",
        "--steps",
        "1",
        "--json",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--scene"));
}

//! `palpate scene plan` (README "scene plan"): the JSON contract on a scene file written here,
//! the VTK region field read back, and each bad input as one line and exit status 2.

use std::path::{Path, PathBuf};

use crate::common::{assert_one_line_error, fresh_dir, palpate, stderr, text};
use palpate::mesh::generate::box_mesh;

/// A 6 × 6 × 3-cell block of 1 cm (648 tets, 196 vertices), base fixed, then `extra` TOML.
const BLOCK: &str = "fix = [\"z<0.0001\"]\n[generated]\nbox_m = [0.06, 0.06, 0.03]\ncells = [6, 6, 3]\n[material]\nyoung_pa = 3000\npoisson = 0.45\n";

/// Writes `scene.toml` (the block then `extra`) in a fresh folder `name`; returns the path.
fn scene_file(name: &str, extra: &str) -> PathBuf {
    let dir = fresh_dir(name);
    let path = dir.join("scene.toml");
    std::fs::write(&path, format!("{BLOCK}{extra}")).unwrap();
    path
}

fn plan(scene: &Path, extra: &[&str]) -> std::process::Output {
    let scene = scene.display().to_string();
    let mut args = vec!["scene", "plan", scene.as_str()];
    args.extend_from_slice(extra);
    palpate(&args)
}

const CUT_BOX: &str = "[[zone]]\nkind = \"cut\"\nshape = \"box\"\nmin_m = [0.0, 0.0, 0.02]\nmax_m = [0.01, 0.02, 0.03]\n[partition]\nmargin_rings = 1\n";

#[test]
fn plan_json_has_the_contract_keys_and_counts() {
    let scene = scene_file("plan-json", CUT_BOX);
    let out = plan(&scene, &["--json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let regions = json["regions"].as_array().unwrap();
    assert_eq!(regions.len(), 2);
    let mut tets = 0;
    for r in regions {
        for key in [
            "model",
            "law",
            "tets",
            "vertices",
            "connection_nodes",
            "table_bytes",
            "step_cost_s",
            "critical_dt_s",
            "why",
        ] {
            assert!(r.get(key).is_some(), "{key} missing: {r}");
        }
        tets += r["tets"].as_u64().unwrap();
        assert!(r["step_cost_s"].as_f64().unwrap() > 0.0);
        assert!(r["table_bytes"].as_u64().unwrap() > 0);
    }
    assert_eq!(tets, 648);
    assert_eq!(regions[0]["model"], "precomputed");
    assert!(regions[0]["critical_dt_s"].is_null());
    assert_eq!(regions[1]["model"], "tensor-mass");
    assert_eq!(regions[1]["law"], "linear");
    assert!(regions[1]["critical_dt_s"].as_f64().unwrap() > 0.0);
    // Brute force on the same mesh: the zone's 1 × 2 × 1 cells (12 tets) plus one ring; the
    // connection nodes are the vertices of both a dynamic and a pre-computed tet.
    let mesh = box_mesh([6, 6, 3], [0.06, 0.06, 0.03]);
    let inside = |t: &[u32; 4]| {
        t.iter().all(|&v| {
            let p = mesh.positions[v as usize];
            p[0] <= 0.01 + 1e-9 && p[1] <= 0.02 + 1e-9 && p[2] >= 0.02 - 1e-9
        })
    };
    let zone_vertices: Vec<u32> = mesh
        .tets
        .iter()
        .filter(|t| inside(t))
        .flatten()
        .copied()
        .collect();
    let dynamic: Vec<bool> = mesh
        .tets
        .iter()
        .map(|t| t.iter().any(|v| zone_vertices.contains(v)))
        .collect();
    assert_eq!(
        regions[1]["tets"].as_u64().unwrap() as usize,
        dynamic.iter().filter(|&&d| d).count()
    );
    let connection = (0..mesh.positions.len() as u32)
        .filter(|&v| {
            let uses = |d: bool| {
                mesh.tets
                    .iter()
                    .zip(&dynamic)
                    .any(|(t, &x)| x == d && t.contains(&v))
            };
            uses(true) && uses(false)
        })
        .count() as u64;
    assert_eq!(json["connection_nodes"].as_u64().unwrap(), connection);
    assert_eq!(regions[0]["connection_nodes"].as_u64().unwrap(), connection);
    assert_eq!(regions[1]["connection_nodes"].as_u64().unwrap(), connection);
    // The text form says the same.
    let out = plan(&scene, &[]);
    assert!(out.status.success(), "{}", stderr(&out));
    let t = text(&out.stdout);
    assert!(
        t.contains("region 1: tensor-mass (linear)") && t.contains("why: "),
        "{t}"
    );
}

#[test]
fn plan_vtk_has_the_region_of_every_tet() {
    let scene = scene_file("plan-vtk", CUT_BOX);
    let vtk = scene.with_file_name("regions.vtk");
    let out = plan(&scene, &["--json", "--vtk", &vtk.display().to_string()]);
    assert!(out.status.success(), "{}", stderr(&out));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let (mesh, _) = palpate::mesh::read_mesh(&vtk).unwrap();
    assert_eq!(mesh.tets.len(), 648);
    let file = std::fs::read_to_string(&vtk).unwrap();
    let values: Vec<u32> = file
        .split("LOOKUP_TABLE default\n")
        .nth(1)
        .unwrap()
        .lines()
        .map(|l| l.parse().unwrap())
        .collect();
    assert!(file.contains("CELL_DATA 648\nSCALARS region int 1\n"));
    assert_eq!(values.len(), 648);
    for id in 0..2u32 {
        let n = values.iter().filter(|&&v| v == id).count() as u64;
        assert_eq!(n, json["regions"][id as usize]["tets"].as_u64().unwrap());
    }
    // The scene file is an input: never overwritten.
    let out = plan(&scene, &["--vtk", &scene.display().to_string()]);
    assert_one_line_error(&out, &["--vtk", "refusing to overwrite an input"]);
}

#[test]
fn no_zone_is_all_precomputed() {
    let scene = scene_file("plan-none", "");
    let out = plan(&scene, &["--json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["regions"].as_array().unwrap().len(), 1);
    assert_eq!(json["connection_nodes"], 0);
}

#[test]
fn bad_zones_are_one_line_errors_naming_the_key() {
    let zone = |body: &str| format!("[[zone]]\nkind = \"cut\"\n{body}");
    let cases: Vec<(String, Vec<&str>)> = vec![
        (
            zone("shape = \"sphere\"\ncenter_m = [1.0, 1.0, 1.0]\nradius_m = 0.01\n"),
            vec!["scene.toml: [[zone]] 1 (cut, sphere) contains no tet of mesh generated box"],
        ),
        (
            format!(
                "{}{}",
                zone("shape = \"sphere\"\ncenter_m = [0.0, 0.0, 0.0]\nradius_m = 0.01\n"),
                zone("shape = \"sphere\"\ncenter_m = [0.0, 0.0, 0.0]\nradius_m = -1\n")
            ),
            vec!["[[zone]] 2 radius_m = -1: must be finite and > 0 m"],
        ),
        (
            zone("shape = \"box\"\nmin_m = [0.0, 0.0, 0.0]\n"),
            vec!["[[zone]] 1 max_m: missing"],
        ),
        (
            zone(
                "shape = \"box\"\nmin_m = [0.0, 0.0, 0.0]\nmax_m = [0.01, 0.01, 0.01]\nradius_m = 1\n",
            ),
            vec!["[[zone]] 1 radius_m: does not apply to shape = \"box\""],
        ),
        (
            zone("shape = \"box\"\nmin_m = [0.02, 0.0, 0.0]\nmax_m = [0.01, 0.01, 0.01]\n"),
            vec!["[[zone]] 1 min_m", "must be below max_m"],
        ),
        (
            zone("shape = \"cone\"\n"),
            vec!["[[zone]] 1 shape = \"cone\": expected"],
        ),
        (
            "[[zone]]\nkind = \"melt\"\nshape = \"box\"\n".into(),
            vec!["[[zone]] 1 kind = \"melt\": expected \"cut\" or \"large-deformation\""],
        ),
        (
            zone("shape = \"path\"\ntrajectory = \"missing.csv\"\nradius_m = 0.01\n"),
            vec!["[[zone]] 1 trajectory", "missing.csv"],
        ),
        (
            "[partition]\nmargin_rings = -1\n".into(),
            vec!["[partition] margin_rings = -1: must be in 0..=64"],
        ),
    ];
    for (i, (extra, needles)) in cases.iter().enumerate() {
        let scene = scene_file(&format!("plan-bad-{i}"), extra);
        assert_one_line_error(&plan(&scene, &["--json"]), needles);
    }
    // A dynamic region that floats: the whole block cut with nothing fixed.
    let dir = fresh_dir("plan-floating");
    let scene = dir.join("scene.toml");
    std::fs::write(
        &scene,
        format!(
            "{}{}",
            BLOCK.replace(
                "fix = [\"z<0.0001\"]\n",
                "[model]\nkind = \"dynamic\"\ndamping_per_s = 2\n"
            ),
            zone("shape = \"box\"\nmin_m = [-1.0, -1.0, -1.0]\nmax_m = [1.0, 1.0, 1.0]\n")
        ),
    )
    .unwrap();
    assert_one_line_error(
        &plan(&scene, &[]),
        &["dynamic region 1 (648 tets", "it floats"],
    );
}

#[test]
fn a_path_zone_reads_the_trajectory_beside_the_scene() {
    let dir = fresh_dir("plan-path");
    std::fs::write(
        dir.join("cut.csv"),
        "t,tool,x,y,z\n0.0,0,0.005,0.005,0.035\n1.0,0,0.005,0.055,0.035\n",
    )
    .unwrap();
    let scene = dir.join("scene.toml");
    std::fs::write(
        &scene,
        format!(
            "{BLOCK}[[zone]]\nkind = \"cut\"\nshape = \"path\"\ntrajectory = \"cut.csv\"\nradius_m = 0.006\n[partition]\nmargin_rings = 0\n"
        ),
    )
    .unwrap();
    let out = plan(&scene, &["--json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    // A line 5 mm above the top face (z = 0.03) along y at x = 0.005 with a 6 mm radius
    // reaches 1 mm into the top layer's first column of cells: 6 cells of 6 tets at most.
    let dynamic = json["regions"][1]["tets"].as_u64().unwrap();
    assert!((1..=36).contains(&dynamic), "{json}");
}

//! `palpate forces MESH --model stvk|neo-hookean|corotational`: the same
//! output as `stvk forces` for St Venant-Kirchhoff, neo-Hookean forces equal
//! to minus the central difference of the printed energy, and the
//! co-rotational energy `null` with zero forces under a rigid rotation.

use crate::common::{palpate, reference, temp};

/// The cube (216 vertices, cells of 0.2 m) with every vertex moved by a
/// deterministic pattern of up to 0.03 m per axis (strains of 10–20 %).
fn deformed_cube() -> Vec<[f64; 3]> {
    rest_cube()
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let wiggle = |k: usize| 0.03 * (((i * 7 + k * 13) % 17) as f64 / 8.0 - 1.0);
            [0, 1, 2].map(|k| p[k] + wiggle(k))
        })
        .collect()
}

/// The cube's rest positions, m.
fn rest_cube() -> Vec<[f64; 3]> {
    let path = reference("meshes/cube.msh");
    palpate::mesh::read_mesh(std::path::Path::new(&path))
        .unwrap()
        .0
        .positions
}

/// Writes `x` as a positions CSV named `name` and returns its path.
fn csv(name: &str, x: &[[f64; 3]]) -> String {
    let path = temp(name);
    let lines: String = x
        .iter()
        .map(|p| format!("{},{},{}\n", p[0], p[1], p[2]))
        .collect();
    std::fs::write(&path, lines).unwrap();
    path.display().to_string()
}

/// The JSON printed by `palpate <command…> MESH --young 5000 --poisson 0.45
/// --deformed CSV --json <extra…>` on the cube.
fn forces(command: &[&str], deformed: &str, extra: &[&str]) -> serde_json::Value {
    let mesh = reference("meshes/cube.msh");
    let args = [
        command,
        &[
            &mesh,
            "--young",
            "5000",
            "--poisson",
            "0.45",
            "--deformed",
            deformed,
            "--json",
        ],
        extra,
    ]
    .concat();
    let out = palpate(&args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

fn rows(json: &serde_json::Value) -> Vec<[f64; 3]> {
    json["forces"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| [0, 1, 2].map(|k| f[k].as_f64().unwrap()))
        .collect()
}

/// `forces --model stvk` prints exactly what `stvk forces` prints.
#[test]
fn forces_stvk_is_stvk_forces() {
    let deformed = csv("forces-stvk.csv", &deformed_cube());
    let new = forces(&["forces"], &deformed, &["--model", "stvk"]);
    let old = forces(&["stvk", "forces"], &deformed, &[]);
    assert_eq!(new, old);
    assert_eq!(rows(&new).len(), 216);
    assert!(new["energy"].as_f64().unwrap() > 0.0);
}

/// Neo-Hookean: the printed forces are minus the central difference of the
/// printed energy on 6 degrees of freedom (step 1e-6 m: truncation and
/// rounding of an energy of ~1e2 J each ~1e-8 N); bound 1e-6 of the largest
/// force, the kernel test's (`kernel::neo_hookean`).
#[test]
fn neo_hookean_forces_are_minus_the_printed_energy_gradient() {
    let x = deformed_cube();
    let law = ["--model", "neo-hookean"];
    let at = forces(&["forces"], &csv("forces-nh.csv", &x), &law);
    let f = rows(&at);
    let scale = f.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    let h = 1e-6;
    for (v, axis) in [(7, 0), (7, 2), (100, 1), (151, 0), (151, 2), (215, 1)] {
        let energy = |delta: f64| {
            let mut moved = x.clone();
            moved[v][axis] += delta;
            let json = forces(
                &["forces"],
                &csv(&format!("forces-nh-{v}-{axis}.csv"), &moved),
                &law,
            );
            json["energy"].as_f64().unwrap()
        };
        let fd = -(energy(h) - energy(-h)) / (2.0 * h);
        let diff = (fd - f[v][axis]).abs();
        assert!(
            diff <= 1e-6 * scale,
            "vertex {v} axis {axis}: {fd} vs {}",
            f[v][axis]
        );
    }
}

/// Co-rotational: `"energy": null`; the rest cube turned by 2 rad about a
/// skew axis has no force (bound 1e-9 of the deformed cube's largest force,
/// rounding).
#[test]
fn corotational_prints_forces_without_energy() {
    let law = ["--model", "corotational"];
    let deformed = forces(
        &["forces"],
        &csv("forces-corot.csv", &deformed_cube()),
        &law,
    );
    assert!(deformed["energy"].is_null(), "{}", deformed["energy"]);
    let scale = rows(&deformed)
        .iter()
        .flatten()
        .fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(scale > 1.0, "{scale}");
    let axis = nalgebra::Vector3::new(1.0, -2.0, 0.5).normalize();
    let q = nalgebra::Rotation3::new(axis * 2.0);
    let turned: Vec<[f64; 3]> = rest_cube()
        .iter()
        .map(|p| (q * nalgebra::Vector3::from(*p)).into())
        .collect();
    let rigid = forces(&["forces"], &csv("forces-corot-rigid.csv", &turned), &law);
    let largest = rows(&rigid)
        .iter()
        .flatten()
        .fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(largest <= 1e-9 * scale, "{largest:e} N vs {scale:e} N");
}

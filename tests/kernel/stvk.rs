//! The St Venant-Kirchhoff force of the tensor-mass model
//! (`palpate_kernel::tensor_mass`, `ElasticLaw::StVenantKirchhoff`) against
//! independent truth: central finite differences of the energy, the JAX
//! reference forces and energies (`tests/reference/svk/`), rigid motions
//! (zero force), the small-strain limit (the linear model), and the
//! incompressibility penalty's closed form on one tet.

use nalgebra::{Rotation3, Vector3};
use palpate::fem::material::Material;
use palpate::mesh::{MeshReport, TetMesh, read_mesh};
use palpate::tensor_mass::evaluate::forces_and_energy;
use palpate_kernel::tensor_mass::{ElasticLaw, StvkForm};
use palpate_tests::{Lcg, json_rows, read_reference_json, reference_dir};

/// Both St Venant-Kirchhoff implementations.
const FORMS: [StvkForm; 2] = [StvkForm::PerTet, StvkForm::Tensors];

fn material() -> Material {
    Material::new(5000.0, 0.45).expect("material")
}

fn cube() -> (TetMesh, MeshReport) {
    read_mesh(&reference_dir().join("meshes/cube.msh")).expect("cube.msh")
}

/// Forces (N) and energy (J) of `mesh` deformed to `x` (m).
fn evaluate(mesh: &TetMesh, law: ElasticLaw, x: &[[f64; 3]]) -> (Vec<[f64; 3]>, f64) {
    forces_and_energy(mesh, &MeshReport::default(), material(), law, None, x).expect("forces")
}

fn stvk(form: StvkForm) -> ElasticLaw {
    ElasticLaw::StVenantKirchhoff(form)
}

/// Largest absolute entry difference and largest reference entry.
fn max_diff(a: &[[f64; 3]], b: &[[f64; 3]]) -> (f64, f64) {
    let diff = a
        .iter()
        .zip(b)
        .flat_map(|(p, q)| (0..3).map(move |i| (p[i] - q[i]).abs()))
        .fold(0.0, f64::max);
    let scale = b.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    (diff, scale)
}

/// The cube (cells of 0.2 m) with every vertex moved by up to `amplitude_m`
/// per axis: nodal noise of 0.04 m gives Green strains of 10–30 %.
fn jiggled(mesh: &TetMesh, amplitude_m: f64, seed: u64) -> Vec<[f64; 3]> {
    let mut rng = Lcg(seed);
    mesh.positions
        .iter()
        .map(|p| p.map(|c| c + amplitude_m * rng.signed()))
        .collect()
}

/// The forces are `−∂W/∂x` of the kernel's own energy, by central
/// differences on every degree of freedom of 40 vertices. Step 1e-6 m:
/// truncation and rounding (W ~ 1e3 J) are each about 1e-7 N against
/// forces up to 1e3 N; bound 1e-8 relative to the largest force (measured
/// 2.7e-7 N, 2.6e-10 relative).
#[test]
fn forces_are_minus_the_energy_gradient() {
    let (mesh, _) = cube();
    let x = jiggled(&mesh, 0.04, 7);
    for form in FORMS {
        let (forces, _) = evaluate(&mesh, stvk(form), &x);
        let h = 1e-6;
        let mut worst: f64 = 0.0;
        for v in (0..mesh.positions.len()).step_by(5).take(40) {
            for axis in 0..3 {
                let mut plus = x.clone();
                plus[v][axis] += h;
                let mut minus = x.clone();
                minus[v][axis] -= h;
                let fd = -(evaluate(&mesh, stvk(form), &plus).1
                    - evaluate(&mesh, stvk(form), &minus).1)
                    / (2.0 * h);
                worst = worst.max((fd - forces[v][axis]).abs());
            }
        }
        let scale = forces.iter().flatten().fold(0.0f64, |m, f| m.max(f.abs()));
        println!("{form:?}: |f − FD| ≤ {worst:.2e} N, forces up to {scale:.3e} N");
        assert!(worst <= 1e-8 * scale, "{form:?}: {worst:e} vs {scale:e}");
    }
}

/// Every configuration of `svk_single_tet.json` and `svk_cube.json` (JAX,
/// f64): forces within 1e-10 of the larger of the largest reference force
/// and the linear model's largest force for the same displacements (at
/// least 1 N), and energy within 1e-10 of the larger of the reference
/// energy and the linear model's (at least 1e-6 J). The linear scale
/// matters for the rigid configurations, whose reference forces and energy
/// are rounding noise: the split form sums quadratic, cubic and quartic
/// terms of the linear model's size, which cancel under a rotation. Measured: forces
/// <= 2e-15 relative (per tet) and 3.5e-14 (split), energies <= 1.2e-14.
#[test]
fn forces_and_energies_match_the_jax_reference() {
    let single = read_reference_json("svk/svk_single_tet.json");
    let tet_mesh = TetMesh {
        positions: json_rows(&single["X"]),
        tets: vec![[0, 1, 2, 3]],
    };
    let (cube, _) = cube();
    for (file, mesh) in [
        (&single, &tet_mesh),
        (&read_reference_json("svk/svk_cube.json"), &cube),
    ] {
        for config in file["configs"].as_array().expect("configs") {
            let name = config["name"].as_str().expect("name");
            let x = json_rows(&config["x"]);
            let reference = json_rows(&config["forces"]);
            let energy = config["energy"].as_f64().expect("energy");
            let (linear_forces, linear_energy) = evaluate(mesh, ElasticLaw::Linear, &x);
            let linear_scale = linear_forces
                .iter()
                .flatten()
                .fold(0.0f64, |m, f| m.max(f.abs()));
            for form in FORMS {
                let (forces, w) = evaluate(mesh, stvk(form), &x);
                let (diff, scale) = max_diff(&forces, &reference);
                let energy_scale = energy.abs().max(linear_energy.abs()).max(1e-6);
                println!(
                    "{name} {form:?}: forces {diff:.2e} of {scale:.2e} N, energy {:.2e} J of {energy:.3e}",
                    (w - energy).abs()
                );
                assert!(
                    diff <= 1e-10 * scale.max(linear_scale).max(1.0),
                    "{name} {form:?}: forces {diff:e}"
                );
                assert!(
                    (w - energy).abs() <= 1e-10 * energy_scale,
                    "{name} {form:?}: energy"
                );
            }
        }
    }
}

/// A rigid rotation (10° to 90° about a skew axis, plus a translation) gives
/// zero St Venant-Kirchhoff force (≤ 1e-9 of the linear model's force for the
/// same motion, which grows like the rotation angle) and zero energy (≤ 1e-12
/// of the linear model's energy; the split form's quadratic, cubic and
/// quartic terms, each of that size, cancel to rounding; measured 1e-12).
#[test]
fn rigid_rotations_give_no_force() {
    let (mesh, _) = cube();
    let axis = Vector3::new(1.0, 2.0, 3.0).normalize();
    let centre = Vector3::new(0.5, 0.5, 0.5);
    for degrees in [10.0f64, 30.0, 60.0, 90.0] {
        let r =
            Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(axis), degrees.to_radians());
        let x: Vec<[f64; 3]> = mesh
            .positions
            .iter()
            .map(|p| {
                (r * (Vector3::from(*p) - centre) + centre + Vector3::new(0.1, -0.2, 0.3)).into()
            })
            .collect();
        let (linear, linear_energy) = evaluate(&mesh, ElasticLaw::Linear, &x);
        let linear_scale = linear.iter().flatten().fold(0.0f64, |m, f| m.max(f.abs()));
        for form in FORMS {
            let (forces, energy) = evaluate(&mesh, stvk(form), &x);
            let worst = forces.iter().flatten().fold(0.0f64, |m, f| m.max(f.abs()));
            println!(
                "{degrees}° {form:?}: |f| ≤ {worst:.1e} N (linear {linear_scale:.2e} N), W = {energy:.1e} J"
            );
            assert!(worst <= 1e-9 * linear_scale, "{degrees}° {form:?}");
            assert!(
                energy.abs() <= 1e-11 * linear_energy,
                "{degrees}° {form:?}: energy {energy:e} of {linear_energy:e}"
            );
        }
    }
}

/// At small strain the non-linear force is the linear one: with nodal noise
/// of 1e-6 m (strain ~1e-5), the difference is second order, bounded by
/// 1e-4 of the force (measured ~1e-5).
#[test]
fn small_strain_limit_is_the_linear_model() {
    let (mesh, _) = cube();
    let x = jiggled(&mesh, 1e-6, 11);
    let (linear, _) = evaluate(&mesh, ElasticLaw::Linear, &x);
    for form in FORMS {
        let (forces, _) = evaluate(&mesh, stvk(form), &x);
        let (diff, scale) = max_diff(&forces, &linear);
        println!(
            "{form:?}: |f_stvk − f_linear| = {:.2e} of {scale:.2e} N",
            diff
        );
        assert!(diff <= 1e-4 * scale, "{form:?}: {diff:e} of {scale:e}");
    }
}

/// Picinbono 2001 §3.2 on one tet scaled by `s` about its centroid (volume
/// `s³ V₀`, no strain energy involved: γ alone): each corner gets
/// `γ sign(ΔV) (ΔV/V₀)²` along the unit outward normal of its opposite face
/// (restoring: inward for a grown tet), to rounding (1e-12 relative).
#[test]
fn incompressibility_penalty_has_the_papers_magnitude_and_direction() {
    let rest = [
        [0.0, 0.0, 0.0],
        [0.03, 0.0, 0.0],
        [0.005, 0.04, 0.0],
        [0.01, 0.01, 0.05],
    ];
    let mesh = TetMesh {
        positions: rest.to_vec(),
        tets: vec![[0, 1, 2, 3]],
    };
    let gamma = 2.5;
    let centroid = rest
        .iter()
        .fold(Vector3::zeros(), |c, p| c + Vector3::from(*p))
        / 4.0;
    for s in [0.8, 1.1, 1.3] {
        let x: Vec<[f64; 3]> = rest
            .iter()
            .map(|p| (centroid + (Vector3::from(*p) - centroid) * s).into())
            .collect();
        let with = forces_and_energy(
            &mesh,
            &MeshReport::default(),
            material(),
            stvk(StvkForm::PerTet),
            Some(gamma),
            &x,
        )
        .expect("forces")
        .0;
        let without = evaluate(&mesh, stvk(StvkForm::PerTet), &x).0;
        let change: f64 = s * s * s - 1.0;
        let faces = [[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]];
        for (p, face) in faces.iter().enumerate() {
            let [b, c, d] = face.map(|v| Vector3::from(x[v]));
            let outward = (c - b).cross(&(d - b)).normalize();
            let expected = outward * (gamma * change * change.abs());
            let got = Vector3::from(with[p]) - Vector3::from(without[p]);
            println!("s = {s}, corner {p}: penalty {got:?}, expected {expected:?}");
            assert!(
                (got - expected).norm() <= 1e-12 * expected.norm(),
                "s = {s}, corner {p}"
            );
        }
    }
}

/// The cut invariant for the non-linear model, through the kernel's own
/// removal path (`TensorMassModel::remove_tet`, hanging tets included): after
/// removing tets, the St Venant-Kirchhoff forces of both forms at a 10–30 %
/// strain deformation equal those of a model built from the mesh without
/// those tets, to 1e-12 of the largest force (the stored terms minus the
/// removed tets' terms equal the rebuilt ones to rounding; measured ~1e-15).
#[test]
fn cutting_equals_rebuilding_without_the_tets() {
    use palpate::table::build::BuildOptions;
    use palpate::table::file::Precision;
    use palpate::tensor_mass::OwnedState;
    use palpate::tensor_mass::run::{f64_table, host_params};
    use palpate_kernel::table::TensorMassTable;
    use palpate_kernel::tensor_mass::TensorMassModel;

    let (mesh, report) = cube();
    let options = BuildOptions::tensor_mass(material(), 1000.0, Vec::new(), Precision::F64);
    let x = jiggled(&mesh, 0.04, 3);
    let u: Vec<[f64; 3]> = x
        .iter()
        .zip(&mesh.positions)
        .map(|(x, p)| [x[0] - p[0], x[1] - p[1], x[2] - p[2]])
        .collect();
    for form in FORMS {
        let params = host_params(&mesh.positions, 0.0).with_law(stvk(form));
        let file = f64_table(&mesh, &report, &options).expect("table");
        let table = TensorMassTable::<f64>::load(file.bytes()).expect("load");
        let mut state = OwnedState::for_table(&table);
        let mut model = TensorMassModel::new(table, state.buffers(), params).expect("model");
        for tet in [0, 1, 2, 3, 4, 5, 300, 301, 302, 749] {
            let _ = model.remove_tet(tet);
        }
        let mut cut = vec![[0.0; 3]; u.len()];
        model.elastic_forces_of(&u, &mut cut);
        let reduced = palpate_tests::live_mesh(&mesh, model.tet_alive());
        let removed = mesh.tets.len() - reduced.tets.len();
        let (rebuilt, _) = evaluate(&reduced, stvk(form), &x);
        let (diff, scale) = max_diff(&cut, &rebuilt);
        println!(
            "{form:?}: {removed} tets removed, |f_cut − f_rebuilt| = {diff:.2e} of {scale:.2e} N"
        );
        assert!(removed >= 10);
        assert!(diff <= 1e-12 * scale, "{form:?}: {diff:e} of {scale:e}");
    }
}

/// The two implementations agree to rounding (f64) on three random
/// deformations of 10–30 % strain: forces within 1e-12 of the largest force
/// and energies within 1e-12 relative (measured: forces 1.1e-15, energies
/// 2e-15).
#[test]
fn both_forms_agree() {
    let (mesh, _) = cube();
    for seed in [21, 22, 23] {
        let x = jiggled(&mesh, 0.04, seed);
        let (per_tet, w_per_tet) = evaluate(&mesh, stvk(StvkForm::PerTet), &x);
        let (tensors, w_tensors) = evaluate(&mesh, stvk(StvkForm::Tensors), &x);
        let (diff, scale) = max_diff(&tensors, &per_tet);
        let energy = (w_tensors - w_per_tet).abs() / w_per_tet;
        println!("seed {seed}: forces {diff:.2e} of {scale:.2e} N, energy {energy:.2e} relative");
        assert!(diff <= 1e-12 * scale, "seed {seed}: forces {diff:e}");
        assert!(energy <= 1e-12, "seed {seed}: energy {energy:e}");
    }
}

//! The dynamic tensor-mass model (`palpate_kernel::tensor_mass`) against
//! independent truth: scikit-fem's global stiffness and lumped masses
//! (`tests/reference/linear/cube_K.csv`, `masses/cube_lumped_mass.csv`), the
//! scikit-fem static contact solution (`linear/cube_contact.json`) as the
//! damped steady state, integrator steps derived by hand for one tet, energy
//! conservation of the symplectic schemes, and the fault state.

use nalgebra::{Matrix2, Vector2, Vector3};
use palpate::fem::material::{Material, TetMaterials};
use palpate::mesh::{MeshReport, TetMesh, boundary_surface, read_mesh};
use palpate::table::build::{BuildOptions, build};
use palpate::table::file::Precision;
use palpate::table::load::TableFile;
use palpate::table::tensor_mass::{TensorMassArrays, write_tensor_mass_table};
use palpate::tensor_mass::OwnedState;
use palpate_kernel::LoadError;
use palpate_kernel::table::TensorMassTable;
use palpate_kernel::tensor_mass::{DynamicParams, Fault, Integrator, StepError, TensorMassModel};
use palpate_tests::{
    json_rows, max_entry_difference, read_reference_json, read_reference_stiffness, reference_dir,
};

const DENSITY: f64 = 1000.0;

fn cube() -> (TetMesh, MeshReport) {
    read_mesh(&reference_dir().join("meshes/cube.msh")).expect("cube.msh")
}

fn options(fix: &[&str], young_pa: f64, poisson: f64) -> BuildOptions {
    BuildOptions::tensor_mass(
        Material::new(young_pa, poisson).expect("material"),
        DENSITY,
        fix.iter().map(|f| f.parse().expect("predicate")).collect(),
        Precision::F64,
    )
}

fn cube_table(fix: &[&str]) -> TableFile {
    let (mesh, report) = cube();
    let bytes = build(&mesh, &report, &options(fix, 5000.0, 0.45))
        .unwrap()
        .bytes;
    TableFile::from_bytes(&bytes)
}

fn params(damping_per_s: f64) -> DynamicParams<f64> {
    DynamicParams::linear(damping_per_s, f64::INFINITY)
}

/// `K u` assembled from the vertex and edge tensors equals scikit-fem's K
/// entry by entry (the tensors are a re-indexing of the global K: MODELS.md
/// §1). Measured 8e-16; bound 1e-12 (rounding of sums of ~24 blocks).
#[test]
fn tensors_and_masses_match_scikit_fem() {
    let file = cube_table(&[]);
    let table = TensorMassTable::<f64>::load(file.bytes()).expect("valid table");
    let reference = read_reference_stiffness();
    let scale = reference.values().fold(0.0f64, |m, x| m.max(x.abs()));
    let mut ours = std::collections::HashMap::new();
    let mut put = |i: usize, j: usize, k: &[f64; 9], transpose: bool| {
        for (e, &x) in k.iter().enumerate() {
            let (a, b) = if transpose {
                (e % 3, e / 3)
            } else {
                (e / 3, e % 3)
            };
            ours.insert((3 * i + a, 3 * j + b), x);
        }
    };
    for (i, k) in table.vertex_tensors().iter().enumerate() {
        put(i, i, k, false);
    }
    let rows = table.edge_row_starts();
    for i in 0..table.vertex_count() {
        for e in rows[i] as usize..rows[i + 1] as usize {
            let j = table.edge_columns()[e] as usize;
            put(i, j, &table.edge_tensors()[e], false);
            put(j, i, &table.edge_tensors()[e], true);
        }
    }
    let worst = max_entry_difference(&ours, &reference);
    println!("tensors vs cube_K.csv: {:e}", worst / scale);
    assert!(worst <= 1e-12 * scale, "relative {:e}", worst / scale);

    let csv = std::fs::read_to_string(reference_dir().join("masses/cube_lumped_mass.csv")).unwrap();
    let masses: Vec<f64> = csv
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("vertex"))
        .map(|l| l.split(',').nth(1).unwrap().parse().unwrap())
        .collect();
    assert_eq!(masses.len(), table.vertex_count());
    for (ours, theirs) in table.masses_kg().iter().zip(&masses) {
        assert!(
            (ours - theirs).abs() <= 1e-12 * theirs,
            "{ours} vs {theirs}"
        );
    }
}

/// Damped dynamics with vertex 194 held at `d` settle to the static solution
/// scikit-fem computed (MODELS.md §3: the quasi-static limit of the dynamic
/// model is the linear FEM). Stopping rule: `max |v| < 1e-13 m/s`; the
/// remaining error is the transient, bound 1e-8 relative (measured 1e-10).
#[test]
fn damped_steady_state_is_the_static_solution() {
    let reference = read_reference_json("linear/cube_contact.json");
    let single = &reference["single_contact"];
    let file = cube_table(&["z<0.001"]);
    let table = TensorMassTable::<f64>::load(file.bytes()).expect("valid table");
    let mut state = OwnedState::for_table(&table);
    // c = 8/s: about critical for the slowest mode (ω ≈ 4 rad/s) of this cube.
    let mut model = TensorMassModel::new(table, state.buffers(), params(8.0)).unwrap();
    model.impose(194, Vector3::new(0.0, 0.0, -0.01)).unwrap();
    let mut steps = 0;
    loop {
        model.step(Integrator::SymplecticEuler, 0.004).unwrap();
        steps += 1;
        let v = model.velocities_m_s().unwrap();
        if v.iter().flatten().all(|x| x.abs() < 1e-13) || steps == 50_000 {
            break;
        }
    }
    let u = model.displacements_m().unwrap();
    let want = json_rows(&single["displacements"]);
    let scale = 0.01;
    let worst = u
        .iter()
        .zip(&want)
        .flat_map(|(a, b)| (0..3).map(move |i| (a[i] - b[i]).abs()))
        .fold(0.0f64, f64::max);
    let mut forces = vec![[0.0; 3]; u.len()];
    model.elastic_forces_n(&mut forces);
    let force_ref: Vec<f64> = single["force"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    let force_err = (0..3)
        .map(|i| (-forces[194][i] - force_ref[i]).abs())
        .fold(0.0f64, f64::max);
    println!(
        "steady state after {steps} steps: displacement error {:e}, force error {:e}",
        worst / scale,
        force_err / 13.6227
    );
    assert!(worst <= 1e-8 * scale, "{:e}", worst / scale);
    assert!(force_err <= 1e-8 * 13.6227, "{force_err:e}");
}

/// The unit right tet with vertices 0, 1, 2 fixed: vertex 3 moves under
/// `K_33 = V diag(μ, μ, λ+2μ)` (its gradient is `a_3 = e_z`, `V = 1/6`), mass
/// `ρV/4`. Each axis is an independent damped oscillator
/// `ü = (F − k u)/m − c u̇`, stepped here by the textbook formula of each
/// scheme; the kernel must agree to rounding (bound 1e-12 relative).
#[test]
fn one_tet_steps_match_hand_derivation() {
    let mesh = TetMesh {
        positions: vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ],
        tets: vec![[0, 1, 2, 3]],
    };
    let opts = options(&["z<0.5"], 1000.0, 0.25);
    let bytes = build(&mesh, &MeshReport::default(), &opts).unwrap().bytes;
    let file = TableFile::from_bytes(&bytes);
    let (lambda, mu) = (400.0, 400.0);
    let volume = 1.0 / 6.0;
    let k = [volume * mu, volume * mu, volume * (lambda + 2.0 * mu)];
    let m = DENSITY * volume / 4.0;
    let (c, dt) = (3.0, 0.01);
    let force = [1.0, -2.0, 3.0];
    let u0 = [0.01, 0.02, -0.03];
    for integrator in Integrator::ALL {
        let table = TensorMassTable::<f64>::load(file.bytes()).unwrap();
        let mut state = OwnedState::for_table(&table);
        let mut model = TensorMassModel::new(table, state.buffers(), params(c)).unwrap();
        model.impose(3, Vector3::from(u0)).unwrap();
        model.release(3).unwrap();
        model.set_external_force(3, Vector3::from(force)).unwrap();
        for _ in 0..3 {
            model.step(integrator, dt).unwrap();
        }
        let got = model.displacements_m().unwrap()[3];
        let got_v = model.velocities_m_s().unwrap()[3];
        for axis in 0..3 {
            let (want_u, want_v) =
                hand_steps(integrator, k[axis], m, c, force[axis], u0[axis], dt, 3);
            let tol = 1e-12 * want_u.abs().max(1e-3);
            assert!(
                (got[axis] - want_u).abs() <= tol,
                "{integrator:?} axis {axis}: {} vs {want_u}",
                got[axis]
            );
            let tol_v = 1e-12 * want_v.abs().max(1e-2);
            assert!(
                (got_v[axis] - want_v).abs() <= tol_v,
                "{integrator:?} v axis {axis}"
            );
        }
    }
}

/// `steps` steps of `integrator` on `m ü = F − k u − c m u̇` from `(u0, 0)`.
#[allow(clippy::too_many_arguments)]
fn hand_steps(
    integrator: Integrator,
    k: f64,
    m: f64,
    c: f64,
    f: f64,
    u0: f64,
    dt: f64,
    steps: usize,
) -> (f64, f64) {
    let accel = |u: f64, v: f64| (f - k * u) / m - c * v;
    let (mut u, mut v, mut u_prev) = (u0, 0.0, u0);
    for _ in 0..steps {
        match integrator {
            Integrator::ExplicitEuler => (u, v) = (u + dt * v, v + dt * accel(u, v)),
            Integrator::SymplecticEuler => {
                v += dt * accel(u, v);
                u += dt * v;
            }
            Integrator::Rk4 => {
                // ẏ = A y + b, y = (u, v).
                let a = Matrix2::new(0.0, 1.0, -k / m, -c);
                let b = Vector2::new(0.0, f / m);
                let rate = |y: Vector2<f64>| a * y + b;
                let y = Vector2::new(u, v);
                let k1 = rate(y);
                let k2 = rate(y + k1 * (dt / 2.0));
                let k3 = rate(y + k2 * (dt / 2.0));
                let k4 = rate(y + k3 * dt);
                let y = y + (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (dt / 6.0);
                (u, v) = (y.x, y.y);
            }
            Integrator::CentralDifference => {
                // Picinbono eq. (19) with γ = c m (damping sign of MODELS.md).
                let lhs = m / (dt * dt) + c * m / (2.0 * dt);
                let next = (f - k * u + 2.0 * m / (dt * dt) * u
                    - (m / (dt * dt) - c * m / (2.0 * dt)) * u_prev)
                    / lhs;
                v = (next - u_prev) / (2.0 * dt);
                u_prev = u;
                u = next;
            }
        }
    }
    (u, v)
}

/// Total energy `½ Σ m v² + ½ uᵀ K u` (J), with `K u = −f_elastic`.
fn total_energy(model: &TensorMassModel<'_, '_, f64>) -> f64 {
    let u = model.displacements_m().unwrap();
    let v = model.velocities_m_s().unwrap();
    let mut f = vec![[0.0; 3]; u.len()];
    model.elastic_forces_n(&mut f);
    let kinetic: f64 = v
        .iter()
        .zip(model.masses_kg())
        .map(|(v, m)| 0.5 * m * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]))
        .sum();
    let elastic: f64 = u
        .iter()
        .zip(&f)
        .map(|(u, f)| -0.5 * (u[0] * f[0] + u[1] * f[1] + u[2] * f[2]))
        .sum();
    kinetic + elastic
}

/// Undamped, below the critical step: the symplectic and central schemes
/// keep the energy (mean of the last 500 steps within 1 % of the first 500
/// over 6000 steps, i.e. no drift), forward Euler gains energy (> 10 %), so
/// the check can fail.
#[test]
fn symplectic_schemes_do_not_drift_euler_does() {
    let file = cube_table(&["z<0.001"]);
    let mean = |e: &[f64]| e.iter().sum::<f64>() / e.len() as f64;
    for integrator in Integrator::ALL {
        let table = TensorMassTable::<f64>::load(file.bytes()).unwrap();
        let mut state = OwnedState::for_table(&table);
        let mut model = TensorMassModel::new(table, state.buffers(), params(0.0)).unwrap();
        model.impose(194, Vector3::new(0.0, 0.0, -0.01)).unwrap();
        model.release(194).unwrap();
        let energies: Vec<f64> = (0..6000)
            .map(|_| {
                model.step(integrator, 0.002).unwrap();
                total_energy(&model)
            })
            .collect();
        let drift = mean(&energies[5500..]) / mean(&energies[..500]) - 1.0;
        println!(
            "{}: energy drift over 6000 steps {drift:+.3e}",
            integrator.name()
        );
        match integrator {
            Integrator::SymplecticEuler | Integrator::CentralDifference => {
                assert!(drift.abs() < 0.01, "{integrator:?} drift {drift}")
            }
            Integrator::ExplicitEuler => assert!(drift > 0.1, "Euler drift {drift}"),
            Integrator::Rk4 => assert!(drift.abs() < 0.01, "RK4 drift {drift}"),
        }
    }
}

/// A step far above the critical one diverges; the fault trips inside the
/// step, and no displacement above the bound is ever readable.
#[test]
fn divergence_faults_before_output_exceeds_the_bound() {
    let file = cube_table(&["z<0.001"]);
    let bound = 0.05;
    for integrator in Integrator::ALL {
        let table = TensorMassTable::<f64>::load(file.bytes()).unwrap();
        let mut state = OwnedState::for_table(&table);
        let mut p = params(0.0);
        p.limits.max_displacement_m = bound;
        let mut model = TensorMassModel::new(table, state.buffers(), p).unwrap();
        model.impose(194, Vector3::new(0.0, 0.0, -0.01)).unwrap();
        model.release(194).unwrap();
        let mut faulted = None;
        for step in 0..200 {
            match model.step(integrator, 0.5) {
                Ok(_) => {
                    let u = model.displacements_m().unwrap();
                    let max = u
                        .iter()
                        .map(|u| Vector3::from(*u).norm())
                        .fold(0.0, f64::max);
                    assert!(max <= bound, "{integrator:?} step {step}: {max} readable");
                }
                Err(StepError::Faulted(fault)) => {
                    faulted = Some(fault);
                    break;
                }
                Err(e) => panic!("{e}"),
            }
        }
        let fault = faulted.unwrap_or_else(|| panic!("{integrator:?} never faulted"));
        assert!(matches!(
            fault,
            Fault::DisplacementBound { .. } | Fault::NonFinite { .. }
        ));
        assert_eq!(model.displacements_m(), Err(fault));
        assert_eq!(
            model.step(integrator, 0.001),
            Err(StepError::Faulted(fault))
        );
        model.reset();
        assert!(model.displacements_m().is_ok());
    }
}

#[test]
fn bad_inputs_are_typed_errors() {
    let file = cube_table(&["z<0.001"]);
    let table = TensorMassTable::<f64>::load(file.bytes()).unwrap();
    let mut state = OwnedState::for_table(&table);
    let mut model = TensorMassModel::new(table, state.buffers(), params(1.0)).unwrap();
    use palpate_kernel::tensor_mass::InputError;
    assert_eq!(
        model.impose(0, Vector3::zeros()),
        Err(InputError::FixedVertex { vertex: 0 })
    );
    assert_eq!(
        model.impose(999, Vector3::zeros()),
        Err(InputError::VertexOutOfRange { vertex: 999 })
    );
    assert_eq!(
        model.set_external_force(194, Vector3::new(f64::NAN, 0.0, 0.0)),
        Err(InputError::NonFinite { vertex: 194 })
    );
    assert_eq!(
        model.step(Integrator::Rk4, -1.0),
        Err(StepError::BadTimeStep)
    );
    assert_eq!(
        model.step(Integrator::Rk4, f64::NAN),
        Err(StepError::BadTimeStep)
    );
}

/// Structural corruption behind a valid checksum is caught at load.
#[test]
fn broken_edge_and_tet_references_are_refused() {
    let (mesh, _) = cube();
    let opts = options(&["z<0.001"], 5000.0, 0.45);
    let fixed: Vec<bool> = mesh.positions.iter().map(|p| p[2] < 0.001).collect();
    let arrays = TensorMassArrays::new(
        &mesh,
        &TetMaterials::uniform(opts.material, mesh.tets.len()),
        DENSITY,
        fixed,
    );
    let load = |arrays: &TensorMassArrays| {
        let triangles = boundary_surface(&mesh).triangles;
        let bytes = write_tensor_mass_table(&mesh, &triangles, arrays, opts.precision);
        let file = TableFile::from_bytes(&bytes);
        TensorMassTable::<f64>::load(file.bytes()).map(|_| ())
    };
    assert_eq!(load(&arrays), Ok(()));
    let mut bad = arrays.clone();
    bad.tet_edges[5][2] = bad.tet_edges[5][3];
    assert_eq!(load(&bad), Err(LoadError::BadTet { tet: 5 }));
    let mut bad = arrays.clone();
    bad.column.swap(0, 1);
    assert_eq!(load(&bad), Err(LoadError::BadEdges { vertex: 0 }));
    let mut bad = arrays.clone();
    bad.neighbours[7][1] = 100_000;
    assert_eq!(load(&bad), Err(LoadError::BadTet { tet: 7 }));
    let mut bad = arrays.clone();
    bad.masses_kg[3] = -1.0;
    assert_eq!(load(&bad), Err(LoadError::BadVertexData { vertex: 3 }));
}

/// Removes every tet crossing the plane `x = 0.5` of the reference cube (a
/// cut), then one more tet next to the cut. Invariants (MODELS.md §1, issue
/// 4): the tensors and masses equal those built from the mesh of the live
/// tets (f64: ≤ 1e-12 relative to the largest entry; measured ~1e-16), every
/// live tet keeps a live face neighbour (no tet hangs by an edge or a
/// vertex), and the model's surface is the host's boundary extraction of the
/// live mesh, face for face.
#[test]
fn removal_equals_rebuild_and_keeps_the_mesh_conformal() {
    let (mesh, _) = cube();
    let opts = options(&["z<0.001"], 5000.0, 0.45);
    let bytes = build(&mesh, &MeshReport::default(), &opts).unwrap().bytes;
    let file = TableFile::from_bytes(&bytes);
    let table = TensorMassTable::<f64>::load(file.bytes()).unwrap();
    let mut state = OwnedState::for_table(&table);
    let mut model = TensorMassModel::new(table, state.buffers(), params(0.0)).unwrap();
    let crosses = |t: &[u32; 4]| {
        let xs = t.map(|v| mesh.positions[v as usize][0]);
        xs.iter().any(|&x| x < 0.5) && xs.iter().any(|&x| x > 0.5)
    };
    let mut removed = 0;
    for (t, tet) in mesh.tets.iter().enumerate() {
        if crosses(tet) && model.tet_alive()[t] {
            removed += model.remove_tet(t as u32).unwrap();
        }
    }
    assert!(removed >= 150, "{removed}");
    let first_cut = mesh.tets.iter().position(crosses).unwrap() as u32;
    assert_eq!(
        model.remove_tet(first_cut),
        Err(palpate_kernel::tensor_mass::RemoveError::AlreadyRemoved { tet: first_cut })
    );
    assert_eq!(
        model.remove_tet(750),
        Err(palpate_kernel::tensor_mass::RemoveError::TetOutOfRange { tet: 750 })
    );

    let live = palpate_tests::live_mesh(&mesh, model.tet_alive());
    let fixed: Vec<bool> = mesh.positions.iter().map(|p| p[2] < 0.001).collect();
    let rebuilt = TensorMassArrays::new(
        &live,
        &TetMaterials::uniform(opts.material, live.tets.len()),
        DENSITY,
        fixed,
    );
    let (worst, scale) = palpate_tests::tensor_difference(&model, &file, &rebuilt);
    println!(
        "tensors after {removed} removals vs rebuild: {:e}",
        worst / scale
    );
    assert!(worst <= 1e-12 * scale, "{:e}", worst / scale);
    for (ours, theirs) in model.masses_kg().iter().zip(&rebuilt.masses_kg) {
        assert!(
            (ours - theirs).abs() <= 1e-12 * DENSITY,
            "{ours} vs {theirs}"
        );
    }

    assert_conformal(&model, &mesh);
}

/// A tet whose face neighbours are all removed hangs by edges and vertices:
/// the removal of its last face neighbour takes it too.
#[test]
fn a_tet_left_hanging_is_removed_with_its_last_neighbour() {
    let file = cube_table(&["z<0.001"]);
    let table = TensorMassTable::<f64>::load(file.bytes()).unwrap();
    let neighbours = table.tet_neighbours()[300];
    let mut state = OwnedState::for_table(&table);
    let mut model = TensorMassModel::new(table, state.buffers(), params(0.0)).unwrap();
    let inner: Vec<u32> = neighbours.into_iter().filter(|&o| o < 750).collect();
    assert_eq!(inner.len(), 4, "tet 300 is interior");
    let counts: Vec<u32> = inner
        .iter()
        .map(|&o| model.remove_tet(o).unwrap())
        .collect();
    assert!(!model.tet_alive()[300]);
    assert_eq!(counts.last(), Some(&2), "{counts:?}");
}

/// The linear model's known failure (MODELS.md §3): it is not rotation
/// invariant. A free cube spun about the vertical axis through its centre
/// (initial velocity `ω ẑ × (p − c)`, no load, no damping) feels no force
/// at all, because linearized rotations are zero-energy modes of `K`; so
/// after turning by θ every point sits at `c + (I + θ[ẑ×])(p − c)`, and the
/// volume grows by exactly `θ²` (the determinant of that map minus one).
/// A rotation-invariant model would keep the volume. Bound 1e-9 relative
/// (the forces are `K` times a linear field: rounding only).
#[test]
fn a_rotated_free_body_swells_by_theta_squared() {
    let (mesh, _) = cube();
    let file = cube_table(&[]);
    println!("rotation   volume gain (measured)   theta^2");
    for degrees in [10.0f64, 30.0, 60.0, 90.0] {
        let table = TensorMassTable::<f64>::load(file.bytes()).unwrap();
        let mut state = OwnedState::for_table(&table);
        let mut model = TensorMassModel::new(table, state.buffers(), params(0.0)).unwrap();
        let omega = 1.0; // rad/s
        for (v, p) in mesh.positions.iter().enumerate() {
            let r = Vector3::new(p[0] - 0.5, p[1] - 0.5, 0.0);
            let velocity = Vector3::z().cross(&r) * omega;
            model.set_velocity(v as u32, velocity).unwrap();
        }
        let theta = degrees.to_radians();
        let steps = 1000;
        let dt = theta / omega / steps as f64;
        for _ in 0..steps {
            model.step(Integrator::SymplecticEuler, dt).unwrap();
        }
        let u = model.displacements_m().unwrap();
        let gain = palpate::tensor_mass::run::volume_change(&mesh, u, model.tet_alive());
        println!(
            "{degrees:>6.0} deg   {:>12.2} %   {:>12.2} %",
            100.0 * gain,
            100.0 * theta * theta
        );
        assert!(
            (gain - theta * theta).abs() <= 1e-9 * theta * theta,
            "{gain} vs {}",
            theta * theta
        );
    }
}

/// Every live tet's face neighbours include a live one, and the model's
/// surface is the host's boundary extraction of the live mesh.
fn assert_conformal(model: &TensorMassModel<'_, '_, f64>, mesh: &TetMesh) {
    let file = cube_table(&[]);
    let table = TensorMassTable::<f64>::load(file.bytes()).unwrap();
    let alive = model.tet_alive();
    for (t, neighbours) in table.tet_neighbours().iter().enumerate() {
        if alive[t] {
            assert!(
                neighbours
                    .iter()
                    .any(|&o| (o as usize) < alive.len() && alive[o as usize]),
                "tet {t} hangs"
            );
        }
    }
    let live = palpate_tests::live_mesh(mesh, alive);
    let canonical = |mut faces: Vec<[u32; 3]>| {
        for f in &mut faces {
            let min = (0..3).min_by_key(|&i| f[i]).unwrap();
            f.rotate_left(min);
        }
        faces.sort_unstable();
        faces
    };
    assert_eq!(
        canonical(model.surface_triangles().collect()),
        canonical(palpate::mesh::boundary_surface(&live).triangles)
    );
}

/// A scalpel swept through the top of the cube removes every tet it touches,
/// at most `capacity` per call, the rest on the next calls; the mesh stays
/// conformal.
#[test]
fn tool_cut_is_bounded_per_call_and_complete() {
    let (mesh, _) = cube();
    let file = cube_table(&["z<0.001"]);
    let table = TensorMassTable::<f64>::load(file.bytes()).unwrap();
    let mut state = OwnedState::for_table(&table);
    let mut model = TensorMassModel::new(table, state.buffers(), params(0.0)).unwrap();
    let (a, b, radius) = (
        Vector3::new(-0.1, 0.5, 0.9),
        Vector3::new(1.1, 0.5, 0.9),
        0.15,
    );
    let touched = |t: &[u32; 4]| {
        t.iter().any(|&v| {
            let p = mesh.positions[v as usize];
            ((p[1] - 0.5).powi(2) + (p[2] - 0.9).powi(2)).sqrt() <= radius
        })
    };
    let expected = mesh.tets.iter().filter(|t| touched(t)).count();
    let mut calls = 0;
    loop {
        let report = model.cut_with_tool(a, b, radius, 10);
        calls += 1;
        assert!(report.removed <= 10 + 4, "{report:?}");
        if !report.pending {
            break;
        }
    }
    for (t, tet) in mesh.tets.iter().enumerate() {
        if touched(tet) {
            assert!(!model.tet_alive()[t], "tet {t} touched but alive");
        }
    }
    assert!(
        calls >= expected.div_ceil(14),
        "{calls} calls for {expected} tets"
    );
    assert_conformal(&model, &mesh);
}

/// Stretching the top layer past a threshold tears exactly the tets whose
/// edges elongate past it; with every criterion off nothing tears.
#[test]
fn tearing_removes_overstretched_tets_only() {
    let (mesh, _) = cube();
    let file = cube_table(&["z<0.001"]);
    let table = TensorMassTable::<f64>::load(file.bytes()).unwrap();
    let mut state = OwnedState::for_table(&table);
    let mut model = TensorMassModel::new(table, state.buffers(), params(0.0)).unwrap();
    // Lift the top face (z = 1) by 0.1: the top layer (height 0.2) stretches
    // by 50 % vertically, everything else is at rest.
    for (v, p) in mesh.positions.iter().enumerate() {
        if p[2] > 0.999 {
            model.impose(v as u32, Vector3::new(0.0, 0.0, 0.1)).unwrap();
        }
    }
    use palpate_kernel::tensor_mass::TearThresholds;
    let off = TearThresholds {
        volume_change: None,
        mean_elongation: None,
        max_elongation: None,
    };
    assert_eq!(model.tear(&off, 1000).removed, 0);
    let tear = TearThresholds {
        max_elongation: Some(0.3),
        ..off
    };
    let mut removed = 0;
    loop {
        let report = model.tear(&tear, 50);
        removed += report.removed;
        if !report.pending {
            break;
        }
    }
    // Every top-layer tet has a vertical edge of the layer (+50 %).
    let top_layer = mesh
        .tets
        .iter()
        .filter(|t| t.iter().any(|&v| mesh.positions[v as usize][2] > 0.999))
        .count();
    assert_eq!(removed as usize, top_layer);
    for (t, tet) in mesh.tets.iter().enumerate() {
        let in_top = tet.iter().any(|&v| mesh.positions[v as usize][2] > 0.999);
        assert_eq!(model.tet_alive()[t], !in_top, "tet {t}");
    }
}

/// The model's edge layout (`kernel/src/tensor_mass/edges.rs`) on `palpate bench`'s
/// cylinder (`cylinder_mesh(0.1, 4, 16)`: 1377 vertices, 6144 tets, 8160
/// edges) and the reference cube: every table edge is stored exactly once,
/// as `K_ij` in row `i` or as `K_ij`ᵀ in row `j`, bit for bit (the layout
/// copies and transposes, it computes nothing); every other lane is padding
/// (zero block, column = its row); a row that had 3 or more table edges of
/// its own holds a multiple of 4 (what bounds `edge_group_count`), and the
/// groups used fit in `edge_group_count`. The cylinder's count, 2051 groups
/// (8204 lanes, 1.005× the edges) in 2083, is what a Python port of the
/// placement rule gives on the mesh `tools/reference/step_baselines.py`
/// writes; every edge in its lower row would take 2512.
#[test]
fn edge_layout_stores_each_edge_once_in_groups_of_4() {
    use palpate_kernel::tensor_mass::{EDGE_LANES, StateBuffers};
    let cylinder = palpate::mesh::generate::cylinder_mesh(0.1, 4, 16);
    let (cube, _) = cube();
    for (mesh, groups_used) in [(cylinder, Some(2051)), (cube, None)] {
        let opts = options(&["z<1e-6"], 5000.0, 0.4);
        let file =
            TableFile::from_bytes(&build(&mesh, &MeshReport::default(), &opts).unwrap().bytes);
        let table = TensorMassTable::<f64>::load(file.bytes()).unwrap();
        let capacity = StateBuffers::edge_group_count(&table);
        let mut state = OwnedState::for_table(&table);
        let model = TensorMassModel::new(table, state.buffers(), params(0.0)).unwrap();
        let (starts, groups) = model.edge_groups();
        let n = table.vertex_count();
        assert_eq!((starts.len(), groups.len()), (n + 1, capacity));
        let used = starts[n] as usize;
        println!(
            "{n} vertices, {} edges: {used} groups of {capacity}",
            table.edge_count()
        );
        assert!(used <= capacity);
        if let Some(expected) = groups_used {
            assert_eq!(used, expected);
        }
        let mut stored = std::collections::HashMap::new();
        for i in 0..n {
            let mut lanes = 0;
            for g in &groups[starts[i] as usize..starts[i + 1] as usize] {
                for l in 0..EDGE_LANES {
                    let (j, k) = (g.columns[l], g.tensors.map(|e| e[l]));
                    if j as usize == i {
                        assert_eq!(k, [0.0; 9], "padding of row {i}");
                    } else {
                        lanes += 1;
                        let key = (i.min(j as usize), i.max(j as usize));
                        assert!(stored.insert(key, (i, k)).is_none(), "{key:?} twice");
                    }
                }
            }
            let own = (table.edge_row_starts()[i + 1] - table.edge_row_starts()[i]) as usize;
            if own >= 3 {
                assert_eq!(lanes % EDGE_LANES, 0, "row {i}: {lanes} edges");
            }
        }
        assert!(groups[used..].iter().all(|g| g.tensors == [[0.0; 4]; 9]));
        assert_eq!(stored.len(), table.edge_count());
        let rows = table.edge_row_starts();
        for i in 0..n {
            for e in rows[i] as usize..rows[i + 1] as usize {
                let j = table.edge_columns()[e] as usize;
                let k = table.edge_tensors()[e];
                let kt: [f64; 9] = core::array::from_fn(|x| k[(x % 3) * 3 + x / 3]);
                let (row, ours) = stored[&(i, j)];
                assert_eq!(ours, if row == i { k } else { kt }, "edge {i}-{j}");
                assert_eq!(model.edge_tensor(i as u32, j as u32), Some(k));
                assert_eq!(model.edge_tensor(j as u32, i as u32), Some(kt));
            }
        }
        assert_eq!(model.edge_tensor(0, 0), None);
    }
}

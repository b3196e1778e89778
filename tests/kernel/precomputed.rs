//! The pre-computed multi-contact model (`palpate_kernel::precomputed`) against
//! independent truth: the scikit-fem reference solutions of
//! `tests/reference/linear/cube_contact.json`, a direct Dirichlet solve of the
//! host's own f64 FEM (`fem::static_solve`), and the constraint residual.
//!
//! Tolerances (relative to the largest value of the compared field). f64
//! tables: table and reference are exact solves of the same linear system, so
//! they agree to rounding amplified by the condition number of the stiffness;
//! measured ≤ 3.1e-15, bound 1e-13. f32 tables: every compliance entry is
//! rounded to f32 (relative 6e-8) and the contact solve runs in f32; measured
//! ≤ 7.9e-8, bound 1e-6 (a contact system with condition number up to ~10
//! stays inside it).

#![allow(clippy::needless_range_loop)] // component loops mirror MODELS.md notation

use nalgebra::Vector3;
use palpate::fem::material::{Material, TetMaterials};
use palpate::fem::static_solve::solve_prescribed;
use palpate::table::file::Precision;
use palpate::table::load::{AnyModel, TableFile};
use palpate_kernel::{Constraint, ContactError, MAX_CONTACTS, PrecomputedModel, Real};
use palpate_tests::{json_rows, read_reference_json, reference_cube_table, rel_max_diff};
use proptest::prelude::*;

/// Per-vertex or per-contact 3-vectors, as f64.
type Rows = Vec<[f64; 3]>;

const F64_TOL: f64 = 1e-13;
const F32_TOL: f64 = 1e-6;

fn with_model<R>(
    file: &TableFile,
    f64_case: impl FnOnce(&PrecomputedModel<'_, f64>) -> R,
    f32_case: impl FnOnce(&PrecomputedModel<'_, f32>) -> R,
) -> R {
    match file.model().expect("valid table") {
        AnyModel::F64(m) => f64_case(&m),
        AnyModel::F32(m) => f32_case(&m),
    }
}

/// Forces and displacements (as f64) for vertex contacts `(v, d)`.
fn solve<T: Real>(
    model: &PrecomputedModel<'_, T>,
    contacts: &[(u32, [f64; 3])],
) -> Result<(Rows, Rows), ContactError> {
    let contacts: Vec<Constraint<T>> = contacts
        .iter()
        .map(|(v, d)| Constraint::at_vertex(*v, Vector3::from(d.map(T::of_f64))))
        .collect();
    let solution = model.contact_forces::<MAX_CONTACTS>(&contacts)?;
    let mut u = vec![[T::zero(); 3]; model.table().vertex_count()];
    model
        .displacements(&solution, &mut u)
        .expect("buffer length");
    let forces = solution
        .contact_forces_n()
        .iter()
        .map(|g| [g.x, g.y, g.z].map(T::as_f64))
        .collect();
    Ok((forces, u.iter().map(|x| x.map(T::as_f64)).collect()))
}

fn flat(rows: &[[f64; 3]]) -> Vec<f64> {
    rows.iter().flatten().copied().collect()
}

fn check_reference_case(case: &str, precision: Precision, tol: f64) {
    let reference = read_reference_json("linear/cube_contact.json");
    let r = &reference[case];
    let (vertices, displacements): (Vec<u32>, Vec<[f64; 3]>) = if case == "single_contact" {
        (
            vec![r["vertex"].as_u64().unwrap() as u32],
            json_rows(&serde_json::json!([r["imposed_displacement"]])),
        )
    } else {
        (
            r["vertices"]
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_u64().unwrap() as u32)
                .collect(),
            json_rows(&r["imposed_displacements"]),
        )
    };
    let forces_ref = if case == "single_contact" {
        json_rows(&serde_json::json!([r["force"]]))
    } else {
        json_rows(&r["forces"])
    };
    let u_ref = json_rows(&r["displacements"]);
    let contacts: Vec<(u32, [f64; 3])> = vertices.into_iter().zip(displacements).collect();
    let file = reference_cube_table(precision);
    let (forces, u) = with_model(
        &file,
        |m| solve(m, &contacts).unwrap(),
        |m| solve(m, &contacts).unwrap(),
    );
    let force_err = rel_max_diff(&flat(&forces), &flat(&forces_ref));
    let u_err = rel_max_diff(&flat(&u), &flat(&u_ref));
    println!(
        "{case} {precision:?}: force rel err {force_err:.2e}, displacement rel err {u_err:.2e}"
    );
    assert!(
        force_err <= tol,
        "{case}: force error {force_err:e} > {tol:e}"
    );
    assert!(
        u_err <= tol,
        "{case}: displacement error {u_err:e} > {tol:e}"
    );
}

#[test]
fn single_contact_matches_scikit_fem_f64() {
    check_reference_case("single_contact", Precision::F64, F64_TOL);
}

#[test]
fn single_contact_matches_scikit_fem_f32() {
    check_reference_case("single_contact", Precision::F32, F32_TOL);
}

#[test]
fn two_contacts_match_scikit_fem_f64() {
    check_reference_case("two_contacts", Precision::F64, F64_TOL);
}

#[test]
fn two_contacts_match_scikit_fem_f32() {
    check_reference_case("two_contacts", Precision::F32, F32_TOL);
}

#[test]
fn single_contact_force_is_the_papers_value() {
    // cube_contact.json: f = C_kk⁻¹ d = (1.47944, 1.47944, -13.62270) N for
    // d = (0, 0, -0.01) m at vertex 194 (5 significant digits in the README).
    let file = reference_cube_table(Precision::F64);
    let (forces, _) = with_model(
        &file,
        |m| solve(m, &[(194, [0.0, 0.0, -0.01])]).unwrap(),
        |_| unreachable!(),
    );
    let expected = [1.47944, 1.47944, -13.62270];
    for (got, want) in forces[0].iter().zip(expected) {
        assert!((got - want).abs() < 1e-5, "{got} vs {want}");
    }
}

/// Four contacts, one of them barycentric, against an independent direct
/// Dirichlet solve of the host's f64 FEM (no compliance table involved).
#[test]
fn four_contacts_match_direct_dirichlet_solve() {
    let contacts = [
        (194u32, [0.0, 0.0, -0.008]),
        (201, [0.002, -0.001, -0.005]),
        (205, [-0.001, 0.0, -0.006]),
        (185, [0.0, 0.003, -0.002]),
    ];
    let (mesh, _) =
        palpate::mesh::read_mesh(&palpate_tests::reference_dir().join("meshes/cube.msh")).unwrap();
    let fixed: Vec<bool> = mesh.positions.iter().map(|p| p[2] < 0.001).collect();
    let (u_direct, f_direct) = solve_prescribed(
        &mesh.positions,
        &mesh.tets,
        &TetMaterials::uniform(Material::new(5000.0, 0.45).unwrap(), mesh.tets.len()),
        &fixed,
        &contacts,
    )
    .unwrap();
    let file = reference_cube_table(Precision::F64);
    let (forces, u) = with_model(&file, |m| solve(m, &contacts).unwrap(), |_| unreachable!());
    assert!(rel_max_diff(&flat(&forces), &flat(&f_direct)) <= F64_TOL);
    assert!(rel_max_diff(&flat(&u), &flat(&u_direct)) <= F64_TOL);
}

/// The paper's figure: superposing single-contact deformations overshoots at
/// nearby contacts; the coupled solve meets every imposed displacement.
#[test]
fn superposition_overshoots_coupled_solve_does_not() {
    // Vertices 194 (0.4,0.4,1) and 195 (0.6,0.4,1) are neighbours on the top face.
    let d = [0.0, 0.0, -0.01];
    let pair = [(194u32, d), (195u32, d)];
    let file = reference_cube_table(Precision::F64);
    let (_, u_single_a) = with_model(&file, |m| solve(m, &pair[..1]).unwrap(), |_| unreachable!());
    let (_, u_single_b) = with_model(&file, |m| solve(m, &pair[1..]).unwrap(), |_| unreachable!());
    let (_, u_coupled) = with_model(&file, |m| solve(m, &pair).unwrap(), |_| unreachable!());
    let superposed_z = u_single_a[194][2] + u_single_b[194][2];
    let overshoot = superposed_z / d[2] - 1.0;
    println!(
        "superposition overshoot at vertex 194: {:.1} %",
        overshoot * 100.0
    );
    assert!(
        overshoot > 0.2,
        "superposition should overshoot by > 20 %, got {overshoot}"
    );
    for (v, dv) in pair {
        for c in 0..3 {
            assert!((u_coupled[v as usize][c] - dv[c]).abs() <= 1e-12);
        }
    }
}

#[test]
fn barycentric_contact_at_a_vertex_is_a_vertex_contact() {
    let file = reference_cube_table(Precision::F64);
    let AnyModel::F64(m) = file.model().unwrap() else {
        unreachable!()
    };
    let d = Vector3::new(0.001, -0.002, -0.007);
    let vertex = m
        .contact_forces::<4>(&[Constraint::at_vertex(194, d)])
        .unwrap();
    // Surface triangle 194-195-201 on the top face, all weight on 194, in
    // each slot (the corners rotated so that 194 is there).
    for weights in [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]] {
        let mut tri = [194, 195, 201];
        let slot = weights.iter().position(|&w| w == 1.0).unwrap();
        tri.rotate_right(slot);
        assert_eq!(tri[slot], 194);
        let bary = m
            .contact_forces::<4>(&[Constraint::on_triangle(tri, weights, d)])
            .unwrap();
        assert_eq!(bary.contact_forces_n(), vertex.contact_forces_n());
    }
}

#[test]
fn barycentric_point_moves_by_the_imposed_displacement() {
    let file = reference_cube_table(Precision::F64);
    let AnyModel::F64(m) = file.model().unwrap() else {
        unreachable!()
    };
    let tri = [194u32, 195, 201];
    let weights = [0.2, 0.5, 0.3];
    let d = Vector3::new(0.001, 0.0, -0.005);
    let s = m
        .contact_forces::<4>(&[
            Constraint::on_triangle(tri, weights, d),
            Constraint::at_vertex(205, Vector3::new(0.0, 0.0, -0.003)),
        ])
        .unwrap();
    let mut u = vec![[0.0; 3]; m.table().vertex_count()];
    m.displacements(&s, &mut u).unwrap();
    for c in 0..3 {
        let point: f64 = tri
            .iter()
            .zip(weights)
            .map(|(&v, w)| w * u[v as usize][c])
            .sum();
        assert!(
            (point - d[c]).abs() < 1e-14,
            "component {c}: {point} vs {}",
            d[c]
        );
    }
}

/// The fast free-index update and the vertex-order update are the same
/// numbers (same arithmetic, so bit-identical), fixed vertices are zero, and
/// a wrong buffer length is refused.
#[test]
fn free_displacements_are_the_vertex_displacements_by_free_index() {
    let file = reference_cube_table(Precision::F32);
    let AnyModel::F32(m) = file.model().unwrap() else {
        unreachable!()
    };
    let s = m
        .contact_forces::<4>(&[
            Constraint::on_triangle(
                [194, 195, 201],
                [0.2, 0.5, 0.3],
                Vector3::new(0.0, 0.001, -0.004),
            ),
            Constraint::at_vertex(205, Vector3::new(0.0, 0.0, -0.003)),
            Constraint::at_vertex(185, Vector3::new(0.002, 0.0, -0.001)),
        ])
        .unwrap();
    let mut by_vertex = vec![[f32::NAN; 3]; m.table().vertex_count()];
    m.displacements(&s, &mut by_vertex).unwrap();
    let mut by_free = vec![[f32::NAN; 3]; m.table().free_count()];
    m.free_displacements(&s, &mut by_free).unwrap();
    for (u, &v) in by_free.iter().zip(m.table().free_vertices()) {
        assert_eq!(
            u.map(f32::to_bits),
            by_vertex[v as usize].map(f32::to_bits),
            "vertex {v}"
        );
    }
    for v in 0..m.table().vertex_count() as u32 {
        if m.table().is_fixed(v) {
            assert_eq!(by_vertex[v as usize], [0.0; 3]);
        }
    }
    assert!(m.free_displacements(&s, &mut by_free[1..]).is_err());
    assert!(m.displacements(&s, &mut by_vertex[1..]).is_err());
}

#[test]
fn contact_errors_are_typed() {
    let file = reference_cube_table(Precision::F32);
    let AnyModel::F32(m) = file.model().unwrap() else {
        unreachable!()
    };
    let d = Vector3::new(0.0f32, 0.0, -0.001);
    let err = |contacts: &[Constraint<f32>]| m.contact_forces::<4>(contacts).unwrap_err();
    // Vertex 0 is on the fixed base; 216 is past the end; 43 = (1,1,1)/5 is interior.
    assert_eq!(
        err(&[Constraint::at_vertex(0, d)]),
        ContactError::FixedVertex {
            contact: 0,
            vertex: 0
        }
    );
    assert_eq!(
        err(&[Constraint::at_vertex(194, d), Constraint::at_vertex(216, d)]),
        ContactError::VertexOutOfRange {
            contact: 1,
            vertex: 216
        }
    );
    assert_eq!(
        err(&[Constraint::at_vertex(43, d)]),
        ContactError::NotOnSurface {
            contact: 0,
            vertex: 43
        }
    );
    assert_eq!(
        err(&[Constraint::at_vertex(194, d), Constraint::at_vertex(194, d)]),
        ContactError::DuplicateContact {
            first: 0,
            second: 1
        }
    );
    let five = [Constraint::at_vertex(194, d); 5];
    assert_eq!(
        err(&five),
        ContactError::TooManyContacts {
            given: 5,
            capacity: 4
        }
    );
    let nan = Vector3::new(f32::NAN, 0.0, 0.0);
    assert_eq!(
        err(&[Constraint::at_vertex(194, nan)]),
        ContactError::NonFiniteInput { contact: 0 }
    );
    let inf = Constraint::on_triangle([194, 195, 200], [f32::INFINITY, 0.0, 0.0], d);
    assert_eq!(err(&[inf]), ContactError::NonFiniteInput { contact: 0 });
    let bad = Constraint::on_triangle([194, 195, 200], [0.5, 0.6, 0.0], d);
    assert_eq!(err(&[bad]), ContactError::BadWeights { contact: 0 });
    let negative = Constraint::on_triangle([194, 195, 200], [1.2, -0.2, 0.0], d);
    assert_eq!(err(&[negative]), ContactError::BadWeights { contact: 0 });
    // The same point twice through the two surface triangles sharing the
    // edge 194-195: singular system.
    let p1 = Constraint::on_triangle([194, 195, 188], [0.5, 0.5, 0.0], d);
    let p2 = Constraint::on_triangle([195, 194, 201], [0.5, 0.5, 0.0], d);
    assert_eq!(err(&[p1, p2]), ContactError::IllConditioned { contact: 1 });
    // All weight on fixed base vertices (surface triangle 0, 1, 7 on z = 0):
    // zero compliance.
    let on_base = Constraint::on_triangle([0, 1, 7], [0.3, 0.3, 0.4], d);
    assert_eq!(err(&[on_base]), ContactError::IllConditioned { contact: 0 });
    // Three surface vertices that are not a surface triangle (194, 195 and
    // 200 span the other diagonal of a top square), and a repeated vertex.
    let across = Constraint::on_triangle([194, 195, 200], [0.2, 0.3, 0.5], d);
    assert_eq!(
        err(&[across]),
        ContactError::NotSurfaceTriangle {
            contact: 0,
            vertices: [194, 195, 200]
        }
    );
    let twice = Constraint::on_triangle([194, 194, 201], [0.2, 0.3, 0.5], d);
    assert_eq!(
        err(&[Constraint::at_vertex(205, d), twice]),
        ContactError::RepeatedVertex {
            contact: 1,
            vertex: 194
        }
    );
    // An empty set is a well-defined zero force.
    let none = m.contact_forces::<4>(&[] as &[Constraint<f32>]).unwrap();
    assert_eq!(none.device_force_n(), Vector3::zeros());
    // A wrong output length is refused, not truncated.
    let s = m
        .contact_forces::<4>(&[Constraint::at_vertex(194, d)])
        .unwrap();
    assert!(m.displacements(&s, &mut [[0.0f32; 3]; 10]).is_err());
}

fn touchable_vertices(m: &PrecomputedModel<'_, f32>) -> Vec<u32> {
    m.table().free_vertices()[..m.table().touchable_count()].to_vec()
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 256,
        failure_persistence: Some(Box::new(
            proptest::test_runner::FileFailurePersistence::Direct("kernel/precomputed.proptest-regressions"),
        )),
        ..ProptestConfig::default()
    })]

    /// Any contact set of 1..=4 touchable-vertex or barycentric contacts with
    /// displacements up to 1 cm: either a typed error, or finite forces whose
    /// displacement field meets every imposed displacement (residual ≤ 1e-3 of
    /// the largest imposed displacement in f32).
    #[test]
    fn contact_solve_is_finite_and_meets_constraints(
        picks in prop::collection::vec((0usize..1000, 0usize..1000, 0usize..1000, 0.0f32..1.0, 0.0f32..1.0, any::<bool>()), 1..=4),
        ds in prop::collection::vec(prop::array::uniform3(-0.01f32..0.01), 4),
    ) {
        thread_local! {
            static FILE: TableFile = reference_cube_table(Precision::F32);
        }
        FILE.with(|file| {
            let AnyModel::F32(m) = file.model().unwrap() else { unreachable!() };
            let touchable = touchable_vertices(&m);
            let surface = m.table().surface_triangles();
            let contacts: Vec<Constraint<f32>> = picks.iter().zip(&ds).map(|(&(a, b, _, wa, wb, bary), d)| {
                let v = |i: usize| touchable[i % touchable.len()];
                let d = Vector3::from(*d);
                if bary {
                    // A surface triangle (three other vertices are refused),
                    // its corners rotated by `b`.
                    let (wa, wb) = (wa * 0.5, wb * 0.5);
                    let mut tri = surface[a % surface.len()];
                    tri.rotate_left(b % 3);
                    Constraint::on_triangle(tri, [wa, wb, 1.0 - wa - wb], d)
                } else {
                    Constraint::at_vertex(v(a), d)
                }
            }).collect();
            match m.contact_forces::<4>(&contacts) {
                Ok(s) => {
                    prop_assert!(s.contact_forces_n().iter().all(|g| g.iter().all(|x| x.is_finite())));
                    let mut u = vec![[0.0f32; 3]; m.table().vertex_count()];
                    m.displacements(&s, &mut u).unwrap();
                    let scale = ds.iter().flatten().fold(1e-6f32, |a, x| a.max(x.abs()));
                    for c in &contacts {
                        let (vs, ws): (Vec<u32>, Vec<f32>) = match c.point {
                            palpate_kernel::ContactPoint::Vertex(v) => (vec![v], vec![1.0]),
                            palpate_kernel::ContactPoint::Triangle { vertices, weights } => (vertices.to_vec(), weights.to_vec()),
                        };
                        for k in 0..3 {
                            let got: f32 = vs.iter().zip(&ws).map(|(&v, w)| w * u[v as usize][k]).sum();
                            prop_assert!((got - c.displacement_m[k]).abs() <= 1e-3 * scale,
                                "residual {} at {:?}", got - c.displacement_m[k], c);
                        }
                    }
                }
                Err(e) => prop_assert!(matches!(e,
                    ContactError::DuplicateContact { .. } | ContactError::IllConditioned { .. }), "{e}"),
            }
            Ok(())
        })?;
    }
}

/// A pre-computed tissue solves in its own buffers: two matrices, the
/// remembered point compliances reused for points that did not change, a
/// set of remembered points in their order factorized in place without
/// replacing them (`PrecomputedModel::solve_into`). Through a sequence that
/// takes every path (four contacts found on the reference cube's top face;
/// the second released, a re-solve from the remembered compliances; the
/// same set again, at rest; the four again, still remembered; two of them
/// in reverse order, half their blocks computed again; the tools moved,
/// new weights; a contact twice, an ill-conditioned set refused, and the
/// moved set again after it; forgotten; four again), each solve equals a fresh `contact_forces` of
/// the same set bit for bit: forces, device force and the stored solution
/// (compared over the set's entries).
#[test]
fn tissue_solves_equal_fresh_solves_through_its_buffers() {
    use palpate_kernel::PrecomputedTable;
    use palpate_kernel::contact::{
        Contact, ContactRefs, ContactWork, SurfaceGeometry, Tissue, lend,
    };
    use palpate_kernel::precomputed::PrecomputedTissue;
    const RADIUS_M: f64 = 0.05;
    let file = reference_cube_table(Precision::F64);
    let table = PrecomputedTable::<f64>::load(file.bytes()).expect("table");
    let model = PrecomputedModel::new(table);
    let geometry = SurfaceGeometry::new(&table);
    let mut tissue = PrecomputedTissue::<f64, MAX_CONTACTS>::new(&table);
    // A sphere a third of its radius into the top face (z = 1 m) at `(x, y)`.
    let contact = |tool: usize, x: f64, y: f64| -> Contact<f64> {
        let tip = Vector3::new(x, y, 1.0 + RADIUS_M * (2.0 / 3.0));
        geometry
            .detect(tool, None, &tip, RADIUS_M, &mut ContactWork::default())
            .expect("a contact on the top face")
    };
    let mut solves = 0;
    let mut check = |tissue: &mut PrecomputedTissue<'_, f64, MAX_CONTACTS>,
                     contacts: &[Contact<f64>]| {
        // The loop lends its records: a copy of the contacts here.
        let mut records = contacts.to_vec();
        let mut set: ContactRefs<'_, f64, MAX_CONTACTS> = lend(&mut records);
        assert_eq!(set.len(), contacts.len());
        let fresh = model.contact_forces::<MAX_CONTACTS>(contacts);
        let solved = tissue.solve(&mut set);
        solves += 1;
        match (fresh, solved) {
            (Ok(fresh), Ok(device_n)) => {
                assert_eq!(device_n, fresh.device_force_n(), "solve {solves}");
                let forces: Vec<_> = set.iter().map(|c| c.force_n).collect();
                assert_eq!(forces, fresh.contact_forces_n(), "solve {solves}");
                assert_eq!(tissue.solution(), Some(&fresh), "solve {solves}");
                assert!(device_n.norm() > 0.0);
            }
            (Err(e), Err(_)) => assert!(matches!(e, ContactError::IllConditioned { .. })),
            (fresh, solved) => panic!("solve {solves}: fresh {fresh:?}, tissue {solved:?}"),
        }
    };
    let four = [
        contact(0, 0.3, 0.3),
        contact(1, 0.5, 0.45),
        contact(2, 0.7, 0.3),
        contact(3, 0.45, 0.7),
    ];
    // `lend` lends at most its capacity, in order.
    let mut records = four;
    let two: ContactRefs<'_, f64, 2> = lend(&mut records);
    assert_eq!(two.iter().map(|c| c.tool).collect::<Vec<_>>(), [0, 1]);
    check(&mut tissue, &four);
    let three = [four[0], four[2], four[3]];
    check(&mut tissue, &three);
    check(&mut tissue, &three);
    check(&mut tissue, &four);
    check(&mut tissue, &[four[3], four[1]]);
    let moved = [
        contact(0, 0.31, 0.29),
        contact(2, 0.69, 0.32),
        contact(3, 0.46, 0.71),
    ];
    check(&mut tissue, &moved);
    check(&mut tissue, &[moved[0], moved[0]]);
    assert_eq!(tissue.solution(), None);
    // After a refusal, as the haptic loop re-solves without the contact.
    check(&mut tissue, &moved);
    tissue.forget();
    check(&mut tissue, &four);
    assert_eq!(solves, 9);
}

//! The quasi-non-linear remap (`palpate_kernel::precomputed::{Remap,
//! QuasiNonLinear}`, Cotin 1999 TVCG §3) against hand-computed values on one
//! vertex and one contact, and the remapped model against the linear one
//! remapped vertex by vertex.

use nalgebra::Vector3;
use palpate::table::file::Precision;
use palpate::table::load::AnyModel;
use palpate_kernel::precomputed::{QuasiNonLinear, Remap, RemapError};
use palpate_kernel::{Constraint, MAX_CONTACTS};
use palpate_tests::reference_cube_table;

/// `φ(x) = x + 2x³` fitted on `[0, 0.01]` m.
fn cubic() -> Remap<f64> {
    Remap::new([1.0, 0.0, 2.0, 0.0, 0.0], 0.01).expect("monotone")
}

/// Hand-computed: `φ(0.005) = 0.005 + 2·0.005³ = 0.00500025`; past the
/// range, the tangent at 0.01 (`φ = 0.010002`, `φ' = 1 + 6·0.01² = 1.0006`)
/// gives `φ(0.02) = 0.010002 + 1.0006·0.01 = 0.020008`; odd for negative
/// inputs. Tolerance 1e-15: a few roundings of values below 0.03.
#[test]
fn remap_matches_hand_computed_values() {
    let phi = cubic();
    for (x, expected) in [
        (0.005, 0.00500025),
        (-0.005, -0.00500025),
        (0.02, 0.020008),
        (0.0, 0.0),
    ] {
        let got = phi.apply(x);
        assert!(
            (got - expected).abs() <= 1e-15,
            "φ({x}) = {got}, expected {expected}"
        );
    }
    assert_eq!(Remap::<f64>::identity().apply(0.37), 0.37);
}

/// One vertex, constraint direction `d̂ = −z` (an imposed displacement
/// `(0, 0, −2 mm)`): `u = (3, 4, −1) mm` splits into the colinear
/// `(0, 0, −1) mm`, kept, and the orthogonal `(3, 4, 0) mm` of amplitude
/// 5 mm, scaled by `φ(0.005)/0.005 = 1.00005`: `(3.00015, 4.0002, −1) mm`.
/// One contact force `g = (0.1, 0, 0.5)` N with `ψ(x) = 2x`: its colinear
/// amplitude `g·d̂ = −0.5` N becomes `−1` N: `(0.1, 0, 1.0)` N.
#[test]
fn quasi_non_linear_splits_and_remaps_one_vertex() {
    let remap = QuasiNonLinear {
        radial: cubic(),
        force: Remap::new([2.0, 0.0, 0.0, 0.0, 0.0], 1.0).expect("linear"),
    };
    let direction = QuasiNonLinear::direction(&Vector3::new(0.0, 0.0, -0.002)).expect("d̂");
    assert_eq!(direction, Vector3::new(0.0, 0.0, -1.0));
    let u = remap.displacement(&direction, Vector3::new(0.003, 0.004, -0.001));
    let expected = Vector3::new(0.00300015, 0.0040002, -0.001);
    assert!((u - expected).amax() <= 1e-15, "{u} vs {expected}");
    let g = remap.force(&direction, Vector3::new(0.1, 0.0, 0.5));
    assert!((g - Vector3::new(0.1, 0.0, 1.0)).amax() <= 1e-15, "{g}");
    // No direction without an imposed displacement: no remap.
    assert!(QuasiNonLinear::<f64>::direction(&Vector3::zeros()).is_none());
}

/// Refusals: a polynomial whose slope `1 − 200x` turns negative past
/// 5 mm is refused at the first sample beyond (33/64 of 10 mm); non-finite
/// coefficients and an empty range are refused.
#[test]
fn bad_remaps_are_refused() {
    assert_eq!(
        Remap::new([1.0, -100.0, 0.0, 0.0, 0.0], 0.01),
        Err(RemapError::Decreasing {
            at: 0.01 * 33.0 / 64.0
        })
    );
    assert_eq!(
        Remap::new([f64::NAN, 0.0, 0.0, 0.0, 0.0], 0.01),
        Err(RemapError::NonFinite)
    );
    assert_eq!(
        Remap::new([1.0, 0.0, 0.0, 0.0, 0.0], 0.0),
        Err(RemapError::EmptyRange)
    );
}

/// The quasi-non-linear model on the reference cube: its device force and
/// every vertex displacement equal the linear model's remapped by the same
/// `QuasiNonLinear` calls (the remap is applied after the solve, never
/// inside it), and the identity remap leaves the force bit for bit and the
/// field to rounding (1e-18 m on millimetre displacements: splitting and
/// recombining a vector costs a few ulps).
#[test]
fn remapped_model_is_the_linear_model_remapped() {
    let file = reference_cube_table(Precision::F64);
    let AnyModel::F64(linear) = file.model().expect("valid table") else {
        panic!("f64 table expected");
    };
    let remap = QuasiNonLinear {
        radial: cubic(),
        force: Remap::new([1.0, 40.0, 0.0, 0.0, 0.0], 1.0).expect("monotone"),
    };
    let d = Vector3::new(0.001, 0.0, -0.004);
    let contacts = [Constraint::at_vertex(194, d)];
    let n = linear.table().vertex_count();
    let solve = |model: &palpate_kernel::PrecomputedModel<'_, f64>| {
        let solution = model
            .contact_forces::<MAX_CONTACTS>(&contacts)
            .expect("solve");
        let mut u = vec![[0.0; 3]; n];
        model.displacements(&solution, &mut u).expect("field");
        (solution.device_force_n(), u)
    };
    let (force, u) = solve(&linear);
    let (same_force, same_u) = solve(&linear.with_remap(QuasiNonLinear {
        radial: Remap::identity(),
        force: Remap::identity(),
    }));
    assert_eq!(force, same_force);
    let worst = u
        .iter()
        .zip(&same_u)
        .map(|(a, b)| (Vector3::from(*a) - Vector3::from(*b)).amax())
        .fold(0.0, f64::max);
    assert!(worst <= 1e-18, "identity remap moved a vertex by {worst} m");
    let (remapped_force, remapped_u) = solve(&linear.with_remap(remap));
    let direction = d.normalize();
    assert!((remapped_force + remap.force(&direction, -force)).amax() <= 1e-15);
    for (lin, nl) in u.iter().zip(&remapped_u) {
        let expected = remap.displacement(&direction, Vector3::from(*lin));
        assert!((expected - Vector3::from(*nl)).amax() <= 1e-18);
    }
    // The remap does change the force: ψ(x) = x + 40x² on the colinear part.
    assert!((remapped_force - force).norm() > 1e-3 * force.norm());
}

/// A pinch: two contacts with opposed imposed displacements (a grasper's
/// jaws). Each contact force is remapped along its own contact's direction
/// (the remap stays on although the displacements sum to zero), and the
/// field is remapped along the larger jaw's direction: the same field as
/// along the other jaw's, since the split does not depend on the sign.
#[test]
fn a_pinch_remaps_each_jaw_along_its_own_direction() {
    let file = reference_cube_table(Precision::F64);
    let AnyModel::F64(linear) = file.model().expect("valid table") else {
        panic!("f64 table expected");
    };
    let remap = QuasiNonLinear {
        radial: cubic(),
        force: Remap::new([1.0, 40.0, 0.0, 0.0, 0.0], 1.0).expect("monotone"),
    };
    let d = Vector3::new(0.0, 0.003, 0.0);
    let contacts = [
        Constraint::at_vertex(194, d),
        Constraint::at_vertex(200, -d * 0.999),
    ];
    let lin = linear
        .contact_forces::<MAX_CONTACTS>(&contacts)
        .expect("linear");
    let nl = linear
        .with_remap(remap)
        .contact_forces::<MAX_CONTACTS>(&contacts)
        .expect("remapped");
    let direction = Vector3::new(0.0, 1.0, 0.0);
    for (g_lin, g_nl) in lin.contact_forces_n().iter().zip(nl.contact_forces_n()) {
        let expected = remap.force(&direction, *g_lin);
        assert!((expected - g_nl).amax() <= 1e-15, "{g_nl} vs {expected}");
        assert!((g_nl - g_lin).norm() > 1e-3 * g_lin.norm(), "remap is on");
    }
    let n = linear.table().vertex_count();
    let (mut u_lin, mut u_nl) = (vec![[0.0; 3]; n], vec![[0.0; 3]; n]);
    linear.displacements(&lin, &mut u_lin).expect("field");
    linear
        .with_remap(remap)
        .displacements(&nl, &mut u_nl)
        .expect("field");
    for (a, b) in u_lin.iter().zip(&u_nl) {
        let along_larger = remap.displacement(&direction, Vector3::from(*a));
        let along_other = remap.displacement(&-direction, Vector3::from(*a));
        assert!((along_larger - Vector3::from(*b)).amax() <= 1e-18);
        assert!((along_other - along_larger).amax() <= 1e-18);
    }
}

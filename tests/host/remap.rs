//! The quasi-non-linear model's host side (`palpate::remap`): the curve
//! format, the least-squares fit against an exact polynomial, and the
//! sample's St Venant-Kirchhoff curves against the small-strain limit
//! (St Venant-Kirchhoff is linear elasticity to first order in the strain,
//! so its remaps must start with slope 1).

use palpate::fem::material::Material;
use palpate::remap::curves::{CurvePoint, parse, to_csv};
use palpate::remap::fit::{fit_curves, fit_polynomial};
use palpate::remap::sample::{Sample, linear_response, stvk_curves};

fn tissue() -> Material {
    Material::new(5000.0, 0.4).expect("material")
}

/// Format: header, three finite columns, increasing compression; errors
/// name the line. Round trip through `to_csv` is exact.
#[test]
fn curve_csv_round_trips_and_refuses_bad_rows() {
    let points = vec![
        CurvePoint {
            force_n: 0.0,
            axial_m: 0.0,
            radial_m: 0.0,
        },
        CurvePoint {
            force_n: 0.125,
            axial_m: 1e-3,
            radial_m: 1.5e-4,
        },
        CurvePoint {
            force_n: 0.3,
            axial_m: 2e-3,
            radial_m: 3.25e-4,
        },
    ];
    assert_eq!(parse(&to_csv(&points)).expect("parse"), points);
    for (text, message) in [
        ("f,a,r\n", "line 1: header"),
        ("force,axial,radial\n0,0,0\n1,0.001\n", "line 3: 2 columns"),
        (
            "force,axial,radial\n0,0,0\n1,x,0\n",
            "line 3: not three numbers",
        ),
        (
            "force,axial,radial\n1,0.002,0\n1,0.001,0\n",
            "line 3: axial compression 0.001 m does not increase",
        ),
        (
            "force,axial,radial\n1,-0.001,0\n",
            "line 2: axial compression -0.001 m is negative",
        ),
        (
            "force,axial,radial\n1,0.001,inf\n",
            "line 2: a value is not finite",
        ),
        ("force,axial,radial\n1,0.001,0\n", "fewer than two rows"),
    ] {
        let error = format!("{:#}", parse(text).expect_err(text));
        assert!(error.contains(message), "{error:?} lacks {message:?}");
    }
}

/// Data on `y = 2x + 3x² − 40x³` (x in m, up to 0.01): the degree-3 fit
/// recovers the coefficients to 1e-9 relative (the scaled Vandermonde
/// system is well conditioned; SVD rounding is 1e-15 of its entries) and
/// the residual is at rounding level.
#[test]
fn least_squares_recovers_an_exact_polynomial() {
    let exact = [2.0, 3.0, -40.0];
    let points: Vec<(f64, f64)> = (1..=12)
        .map(|i| {
            let x = 0.01 * f64::from(i) / 12.0;
            (x, exact[0] * x + exact[1] * x * x + exact[2] * x * x * x)
        })
        .collect();
    let fit = fit_polynomial(&points, 3).expect("fit");
    for (c, e) in fit.coefficients.iter().zip(exact) {
        assert!((c - e).abs() <= 1e-9 * e.abs(), "{c} vs {e}");
    }
    assert_eq!(&fit.coefficients[3..], &[0.0, 0.0]);
    assert!(fit.max_residual <= 1e-15, "{}", fit.max_residual);
    assert_eq!(fit.x_max, 0.01);
    assert!(fit_polynomial(&points, 6).is_err());
}

/// The sample compressed by St Venant-Kirchhoff, 20 mm × 4 mm (the
/// generated default's shape), E = 5 kPa, ν = 0.4. At 0.1 % strain the
/// curves are linear elasticity's to first order: the measured force and
/// radial displacement within 0.5 % of the linear sample's (the
/// second-order term is about the strain, 0.1 %, times a factor of order
/// 1–3). Up to 25 % the fitted remaps are monotone, fit the data within
/// 1 % of its range, and the force curve bends: St Venant-Kirchhoff softens
/// in compression, so `ψ` falls below the identity.
#[test]
fn stvk_sample_curves_start_linear_and_soften() {
    let sample = Sample::new(0.02, 0.004, tissue()).expect("sample");
    let linear = linear_response(&sample).expect("linear");
    println!("linear: {linear:?}");
    let small = stvk_curves(&sample, 0.001, 1).expect("small strain");
    let p = small[1];
    let force_ratio = p.force_n / (linear.force_n_per_m * p.axial_m);
    let radial_ratio = p.radial_m / (linear.radial_per_axial * p.axial_m);
    println!("0.1 %: force ratio {force_ratio}, radial ratio {radial_ratio}");
    assert!((force_ratio - 1.0).abs() <= 5e-3);
    assert!((radial_ratio - 1.0).abs() <= 5e-3);

    let curves = stvk_curves(&sample, 0.25, 8).expect("curves");
    for p in &curves {
        println!(
            "axial {:.3e} m: force {:.4e} N (linear {:.4e}), radial {:.4e} m (linear {:.4e})",
            p.axial_m,
            p.force_n,
            linear.force_n_per_m * p.axial_m,
            p.radial_m,
            linear.radial_per_axial * p.axial_m
        );
    }
    let fitted = fit_curves(&curves, &linear, 3).expect("fit");
    println!("{fitted:?}");
    let remap = fitted.kernel::<f64>().expect("monotone remaps");
    let last = curves.last().expect("points");
    assert!(fitted.force.max_residual <= 0.01 * last.force_n);
    assert!(fitted.radial.max_residual <= 0.01 * last.radial_m.abs());
    let linear_force = linear.force_n_per_m * last.axial_m;
    assert!(remap.force.apply(linear_force) < linear_force);
}

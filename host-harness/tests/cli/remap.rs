//! `palpate remap fit` (README "The quasi-non-linear pre-computed model"):
//! the generated fit's JSON, the same fit from its own curves written back
//! (`--curves-out` then `--curves`), and bad inputs as one line, exit 2.

use crate::common::{assert_one_line_error, fresh_dir, palpate, stderr};

fn fit(extra: &[&str]) -> std::process::Output {
    let mut args = vec!["remap", "fit", "--young", "5000", "--poisson", "0.4"];
    args.extend_from_slice(extra);
    palpate(&args)
}

/// The generated St Venant-Kirchhoff curves' fit, then the fit of the same
/// curves read from the CSV it wrote: identical coefficients (the CSV
/// keeps every `f64` digit). The force remap softens: `ψ` has slope 1 at
/// zero to 0.2 % (St Venant-Kirchhoff is linear elasticity at small
/// strain; the degree-3 fit's first coefficient measured 0.99846).
#[test]
fn fit_round_trips_through_its_curves() {
    let dir = fresh_dir("remap-fit");
    let (json, csv, again) = (
        dir.join("fit.json"),
        dir.join("c.csv"),
        dir.join("again.json"),
    );
    let out = fit(&[
        "--out",
        json.to_str().unwrap(),
        "--curves-out",
        csv.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let first: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(first["source"], "st-venant-kirchhoff-sample");
    let slope = first["fit"]["force"]["coefficients"][0].as_f64().unwrap();
    assert!((slope - 1.0).abs() <= 2e-3, "ψ'(0) = {slope}");
    let out = fit(&[
        "--curves",
        csv.to_str().unwrap(),
        "--out",
        again.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let second: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&again).unwrap()).unwrap();
    assert_eq!(second["source"], "measured");
    assert_eq!(first["fit"], second["fit"]);
}

#[test]
fn bad_inputs_are_one_line_errors() {
    let dir = fresh_dir("remap-bad");
    let csv = dir.join("bad.csv");
    std::fs::write(&csv, "force,axial,radial\n0.1,0.001,0\n0.2,0.0005,0\n").unwrap();
    let out_path = dir.join("out.json");
    let out = fit(&[
        "--curves",
        csv.to_str().unwrap(),
        "--out",
        out_path.to_str().unwrap(),
    ]);
    assert_one_line_error(
        &out,
        &["line 3: axial compression 0.0005 m does not increase"],
    );
    let out = fit(&[
        "--curves",
        csv.to_str().unwrap(),
        "--out",
        csv.to_str().unwrap(),
    ]);
    assert_one_line_error(&out, &["refusing to overwrite an input"]);
    let out = fit(&["--degree", "9", "--out", out_path.to_str().unwrap()]);
    assert_one_line_error(&out, &["--degree 9: must be in 1..=5"]);
    assert!(!out_path.exists());
}

//! `palpate chart --quick` (README "Speed against accuracy"): the files it
//! writes and the JSON's keys; the quasi-non-linear pre-computed model on
//! the reference mesh is the cheapest within 1 % under the small press and
//! on its Pareto front (measured: tip error 4.9e-5 against the Newton St
//! Venant-Kirchhoff reference at 13.6 µs per step, where the linear models
//! are 1.6 % off; the other runs within 1 % there, St Venant-Kirchhoff
//! relaxed (4.6e-7: the reference's own law and mesh) and with the penalty
//! (0.41 %), cost 25.5 and 69 µs per step); the SVGs carry their text as
//! glyph outlines.

mod common;

use common::{fresh_dir, palpate, stderr};

#[test]
fn quick_chart_writes_report_charts_and_json() {
    let dir = fresh_dir("chart-quick");
    let out = palpate(&["chart", "--quick", "--json", "--out", dir.to_str().unwrap()]);
    assert!(out.status.success(), "{}", stderr(&out));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    for file in [
        "report.md",
        "index.html",
        "study.json",
        "pareto-press-1.png",
        "pareto-press-1.svg",
        "cost-mesh.png",
        "stability-symplectic.svg",
        "volume.png",
    ] {
        let meta = std::fs::metadata(dir.join(file)).unwrap_or_else(|e| panic!("{file}: {e}"));
        assert!(meta.len() > 1000, "{file}: {} bytes", meta.len());
    }
    // The SVG's text is glyph outlines: no <text>, no font named.
    let svg = std::fs::read_to_string(dir.join("pareto-press-1.svg")).unwrap();
    assert!(!svg.contains("<text") && !svg.contains("font-family"));
    assert!(svg.matches("<path d=\"M").count() > 10);
    let png = std::fs::read(dir.join("cost-mesh.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    let press = &json["summary"]["press-1"];
    assert_eq!(
        press["cheapest_within_percent"]["1"],
        "precomputed-quasi on 2x10"
    );
    let front: Vec<&str> = press["pareto"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    assert!(front.contains(&"precomputed-quasi on 2x10"), "{front:?}");
    assert_eq!(json["study"]["stability"].as_array().unwrap().len(), 4);
    let report = std::fs::read_to_string(dir.join("report.md")).unwrap();
    assert!(report.contains("## Cheapest model within an error bound"));
    assert!(report.contains("## Where the methods fail"));
}

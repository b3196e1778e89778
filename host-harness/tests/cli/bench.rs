//! `palpate bench` (its JSON contract and its limits) and `palpate dynamic
//! run --precision`. No timed assertion: the timings are checked for their
//! shape (positive, ordered quantiles), never for their value.

use crate::common::{assert_one_line_error, palpate, reference};
use palpate::fem::material::Material;
use palpate::mesh::read_mesh;
use palpate::table::build::{BuildOptions, build};
use palpate::table::file::Precision;
use palpate::table::load::TableFile;
use palpate::tensor_mass::OwnedState;
use palpate_kernel::table::TensorMassTable;
use palpate_kernel::tensor_mass::{DynamicParams, TensorMassModel};

/// `palpate bench` on the reference cube (216 vertices, 750 tets, base
/// fixed) with `extra`, sampled briefly (2 samples of 0.2 ms, no warm-up)
/// unless `extra` says otherwise.
fn bench(extra: &[&str]) -> std::process::Output {
    let mesh = reference("meshes/cube.msh");
    let mut args = vec![
        "bench",
        &mesh,
        "--young",
        "5000",
        "--poisson",
        "0.45",
        "--density",
        "1000",
        "--fix",
        "z<0.001",
    ];
    for [flag, value] in [
        ["--samples", "2"],
        ["--warmup", "0"],
        ["--sample-ms", "0.2"],
    ] {
        if !extra.contains(&flag) {
            args.extend([flag, value]);
        }
    }
    args.extend_from_slice(extra);
    palpate(&args)
}

fn lines(out: &std::process::Output) -> Vec<serde_json::Value> {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout.clone())
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

/// The bytes one linear symplectic step reads in f32, counted by hand from
/// the arrays of `kernel/src/tensor_mass` (independently of
/// `StepCounts::step_bytes`): vertex tensors 36 N, the model's edge groups
/// 160 G (4 blocks of 9 f32 and 4 columns of 4 bytes) and their row starts
/// 4 (N + 1), `u` and `f` 12 N each in the force pass; `u`, `v`, `f`,
/// external forces 12 N each, masses 4 N and modes 1 N in the vertex pass.
fn linear_symplectic_f32_bytes(vertices: u64, groups: u64) -> u64 {
    let n = vertices;
    36 * n + 160 * groups + 4 * (n + 1) + 24 * n + 48 * n + 4 * n + n
}

#[test]
fn bench_prints_one_json_object_per_measurement() {
    let out = bench(&[
        "--models",
        "precomputed,linear,stvk-incompressible",
        "--integrators",
        "symplectic,rk4",
        "--precision",
        "f32",
        "--dispatch",
        "portable",
        "--json",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    let records = lines(&out);
    // 4 force paths, 4 updates, 4 ticks; 2 laws × 2 integrators.
    assert_eq!(records.len(), 12 + 4, "{stderr}");
    // The estimate, printed before the run, names the same count.
    assert!(stderr.contains("16 measurements, estimated"), "{stderr}");
    let edge_groups = {
        let (mesh, report) =
            read_mesh(std::path::Path::new(&reference("meshes/cube.msh"))).unwrap();
        let options = BuildOptions::tensor_mass(
            Material::new(5000.0, 0.45).unwrap(),
            1000.0,
            vec!["z<0.001".parse().unwrap()],
            Precision::F32,
        );
        let file = TableFile::from_bytes(&build(&mesh, &report, &options).unwrap().bytes);
        let table = TensorMassTable::<f32>::load(file.bytes()).unwrap();
        let mut state = OwnedState::for_table(&table);
        let params = DynamicParams::linear(0.0, 1.0);
        let model = TensorMassModel::new(table, state.buffers(), params).unwrap();
        u64::from(model.edge_groups().0[table.vertex_count()])
    };
    let mut groups = std::collections::BTreeMap::new();
    for r in &records {
        assert_eq!(r["vertices"], 216, "{r}");
        assert_eq!(r["tets"], 750, "{r}");
        assert_eq!(r["precision"], "f32");
        assert_eq!(r["dispatch"], "portable");
        let f = |k: &str| r[k].as_f64().unwrap();
        assert!(f("min_s") > 0.0, "{r}");
        assert!(f("min_s") <= f("q1_s") && f("q1_s") <= f("median_s"), "{r}");
        assert!(f("median_s") <= f("q3_s") && f("q3_s") <= f("max_s"), "{r}");
        assert_eq!(r["samples"], 2);
        assert!(r["iterations"].as_u64().unwrap() >= 1);
        let group = r["group"].as_str().unwrap();
        *groups.entry(group.to_string()).or_insert(0) += 1;
        let roofline = group == "step" || group == "displacement-update";
        assert_eq!(!r["bytes_read"].is_null(), roofline, "{r}");
        assert_eq!(!r["copy_median_s"].is_null(), roofline, "{r}");
        if roofline {
            let ratio = f("ratio_to_copy");
            assert!((ratio - f("median_s") / f("copy_median_s")).abs() <= 1e-12 * ratio);
        }
        match group {
            "step" => {
                assert_eq!(r["faults"], 0, "{r}");
                assert!(r["contacts"].is_null());
                let integrator = r["integrator"].as_str().unwrap();
                assert!(["symplectic", "rk4"].contains(&integrator), "{r}");
                if r["model"] == "linear" && integrator == "symplectic" {
                    let want = linear_symplectic_f32_bytes(216, edge_groups);
                    assert_eq!(r["bytes_read"].as_u64(), Some(want), "{r}");
                }
            }
            _ => {
                assert_eq!(r["model"], "precomputed");
                assert!(r["integrator"].is_null());
                let m = r["contacts"].as_u64().unwrap();
                assert!((1..=4).contains(&m), "{r}");
            }
        }
    }
    let want: std::collections::BTreeMap<String, i32> = [
        ("displacement-update", 4),
        ("force-path", 4),
        ("haptic-tick", 4),
        ("step", 4),
    ]
    .map(|(g, n)| (g.to_string(), n))
    .into();
    assert_eq!(groups, want);
}

#[test]
fn bench_measures_both_precisions_and_dispatches() {
    let out = bench(&[
        "--models",
        "stvk",
        "--integrators",
        "central",
        "--dispatch",
        "both",
        "--json",
    ]);
    let records = lines(&out);
    let key = |r: &serde_json::Value| {
        (
            r["precision"].as_str().unwrap().to_string(),
            r["dispatch"].as_str().unwrap().to_string(),
        )
    };
    let keys: std::collections::BTreeSet<_> = records.iter().map(key).collect();
    // Both precisions; the portable passes and, on a CPU with AVX2 and FMA,
    // the dispatched ones.
    for precision in ["f32", "f64"] {
        assert!(keys.contains(&(precision.to_string(), "portable".to_string())));
    }
    assert!(records.len() == 2 || records.len() == 4, "{records:?}");
    for r in &records {
        let dispatch = r["dispatch"].as_str().unwrap();
        assert!(
            ["portable", "avx2+fma", "avx512"].contains(&dispatch),
            "{r}"
        );
        // f64 reads twice the scalars of f32: more bytes.
        assert!(r["bytes_read"].as_u64().unwrap() > 0);
    }
    // The table: a header, then one line per measurement.
    let out = bench(&[
        "--models",
        "linear",
        "--integrators",
        "euler",
        "--precision",
        "f64",
    ]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    let rows: Vec<&str> = text.lines().collect();
    assert_eq!(rows.len(), 2, "{text}");
    assert!(rows[0].starts_with("measurement"), "{text}");
    assert!(
        rows[1].starts_with("step linear/euler") && rows[1].contains("f64"),
        "{text}"
    );
}

#[test]
fn bench_refuses_runs_beyond_its_limits_before_building() {
    assert_one_line_error(
        &bench(&["--samples", "0"]),
        &["--samples must be at least 1"],
    );
    assert_one_line_error(
        &bench(&["--samples", "9999", "--warmup", "2"]),
        &["MAX_BENCH_SAMPLES"],
    );
    assert_one_line_error(
        &bench(&["--sample-ms", "20000"]),
        &["at most 10000 ms", "MAX_BENCH_SAMPLE_S"],
    );
    // 5000 samples of 10 s each: far beyond an hour, refused from the
    // estimate (before any table is built; the message names the count).
    assert_one_line_error(
        &bench(&["--samples", "5000", "--sample-ms", "10000"]),
        &["MAX_BENCH_ESTIMATE_S", "measurements estimated at"],
    );
    let out = bench(&["--models", "nonsense"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("invalid value 'nonsense'"));
}

/// `dynamic run --precision f32` against the default f64 on the reference
/// cube pressed at vertex 194 (200 symplectic steps of 4 ms): the same
/// JSON; displacements equal to f64 within 1e-5 of the largest
/// displacement for the linear law (measured 3.0e-7: the f32 tables round
/// each tensor to 6e-8 relative and 200 steps accumulate it) and within
/// 1e-3 for St Venant-Kirchhoff per tet (measured 1.7e-5: `E = ½(FᵀF − I)`
/// cancels at small strain, losing ε₃₂/strain ≈ 6e-8/1e-3 of E). And they
/// differ from f64 (the flag takes effect).
#[test]
fn dynamic_run_in_f32_matches_f64() {
    let mesh = reference("meshes/cube.msh");
    let run = |model: &str, precision: &str| -> Vec<f64> {
        let out = palpate(&[
            "dynamic",
            "run",
            &mesh,
            "--young",
            "5000",
            "--poisson",
            "0.45",
            "--density",
            "1000",
            "--fix",
            "z<0.001",
            "--damping",
            "8",
            "--load",
            "194:0,0,-1",
            "--integrator",
            "symplectic",
            "--dt",
            "0.004",
            "--steps",
            "200",
            "--model",
            model,
            "--precision",
            precision,
            "--json",
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert!(json["fault"].is_null());
        json["displacements"]
            .as_array()
            .unwrap()
            .iter()
            .flat_map(|u| u.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()))
            .collect()
    };
    for (model, bound) in [("linear", 1e-5), ("stvk", 1e-3)] {
        let (u64, u32) = (run(model, "f64"), run(model, "f32"));
        assert_eq!(u64.len(), 3 * 216);
        let largest = u64.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let diff = u64
            .iter()
            .zip(&u32)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        println!(
            "{model}: f32 vs f64, largest difference {:.2e} of the largest displacement",
            diff / largest
        );
        assert!(largest > 1e-4, "the cube moved");
        assert!(
            diff > 0.0 && diff <= bound * largest,
            "{model}: {diff} vs {largest}"
        );
    }
    let scene_f32 = palpate(&[
        "dynamic",
        "run",
        "--scene",
        "built-in-hybrid",
        "--damping",
        "1",
        "--integrator",
        "symplectic",
        "--dt",
        "1e-4",
        "--steps",
        "1",
        "--precision",
        "f32",
        "--json",
    ]);
    assert_one_line_error(&scene_f32, &["a hybrid scene runs in f64 only"]);
}

/// `bench --scene built-in-dynamic --json --threads 2`, sampled once: one
/// JSON object with the documented fields; the physics update first, then
/// the tick with 1, 2, … tool points; every cost finite and positive, the
/// quartiles around the median, each period the scene's (a physics update
/// every 10 ticks of 1 kHz: 10 ms; a tick 1 ms) and the real-time factor
/// `period_s / median_s` (to 1e-12 relative: one division of the printed
/// numbers, round-tripped exactly by the JSON's shortest form).
#[test]
fn bench_scene_prints_each_stage_against_its_period() {
    let out = palpate(&[
        "bench",
        "--scene",
        "built-in-dynamic",
        "--json",
        "--threads",
        "2",
        "--samples",
        "1",
        "--warmup",
        "0",
        "--sample-ms",
        "0.1",
    ]);
    let objects = lines(&out);
    assert_eq!(objects.len(), 1, "one JSON object");
    let o = &objects[0];
    assert_eq!(o["model"], "dynamic");
    assert_eq!(o["scene"], "built-in dynamic scene");
    assert_eq!(o["vertices"], 1183);
    assert_eq!(o["tets"], 5184);
    assert_eq!(o["dynamic_tets"], 5184);
    assert_eq!(o["threads"], 2);
    let stages = o["stages"].as_array().unwrap();
    assert_eq!(stages[0]["stage"], "physics-update");
    let ticks = &stages[1..];
    assert!(!ticks.is_empty() && ticks.len() <= 4, "{stages:?}");
    for (k, s) in ticks.iter().enumerate() {
        assert_eq!(s["stage"], "haptic-tick");
        assert_eq!(s["tool_points"], k + 1);
    }
    for s in stages {
        let f = |key: &str| s[key].as_f64().unwrap_or_else(|| panic!("{key} in {s}"));
        let (median, q1, q3, period) = (f("median_s"), f("q1_s"), f("q3_s"), f("period_s"));
        assert!(median.is_finite() && median > 0.0, "{s}");
        assert!(q1 <= median && median <= q3, "{s}");
        let expected = if s["stage"] == "physics-update" {
            0.01
        } else {
            0.001
        };
        assert!((period - expected).abs() < 1e-12, "{s}");
        let factor = f("real_time_factor");
        assert!((factor - period / median).abs() <= 1e-12 * factor, "{s}");
        assert!(s["contacts"].as_u64().unwrap() <= s["tool_points"].as_u64().unwrap());
        assert_eq!(s["samples"], 1);
    }
}

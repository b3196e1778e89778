//! The `palpate` command-line contract (README.md): exact commands, JSON
//! shapes, and exit status 2 with a one-line error for bad input.

use crate::common::{
    assert_one_line_error, build_cube, build_cube_table, fresh_dir, palpate, reference, temp,
};
use std::process::Output;

#[test]
fn build_info_and_solve_match_the_reference() {
    let table = temp("cube64.tbl");
    build_cube_table(&table, &["--precision", "f64", "--tool-radius", "0.05"]);
    let table_str = table.display().to_string();
    let info = palpate(&["tables", "info", &table_str]);
    assert!(info.status.success());
    let text = String::from_utf8_lossy(&info.stdout);
    assert!(
        text.contains("vertices: 216") && text.contains("checksum: ok"),
        "{text}"
    );
    // The cube's lists for a 5 cm tool (`kernel::candidates` checks them).
    assert!(
        text.contains(
            "contact candidates: per-cell lists for tools of radius up to 50.000 mm over 8 x 8 x 8 \
             cells of 141.421 mm, at most 8 triangles per cell (a larger tool walks 27 cells: at \
             most 366)"
        ),
        "{text}"
    );

    let out = palpate(&[
        "precomputed",
        "solve",
        &table_str,
        "--contact",
        "194:0,0,-0.01",
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["displacements"].as_array().unwrap().len(), 216);
    let f = &json["contact_forces"][0];
    // cube_contact.json single_contact: (1.47944, 1.47944, -13.62270) N.
    for (i, want) in [1.47944, 1.47944, -13.62270].iter().enumerate() {
        assert!((f[i].as_f64().unwrap() - want).abs() < 1e-5);
        assert!((json["device_force"][i].as_f64().unwrap() + want).abs() < 1e-5);
    }
}

#[test]
fn contacts_come_out_in_argument_order() {
    let table = temp("cube32.tbl");
    build_cube_table(&table, &[]);
    let table_str = table.display().to_string();
    let out = palpate(&[
        "precomputed",
        "solve",
        &table_str,
        "--contact-bary",
        "194,195,201@0.2,0.5,0.3:0,0,-0.004",
        "--contact",
        "205:0,0,-0.002",
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let forces = json["contact_forces"].as_array().unwrap();
    assert_eq!(forces.len(), 2);
    // Pressing harder on the first (barycentric) contact: its force is larger.
    let z = |i: usize| forces[i][2].as_f64().unwrap();
    assert!(z(0) < z(1) && z(1) < 0.0, "{forces:?}");
}

#[test]
fn build_tensor_mass_table_needs_density() {
    let table = temp("cube-tensor-mass.tbl");
    build_cube_table(&table, &["--kind", "tensor-mass", "--density", "1000"]);
    let file = palpate::table::load::TableFile::read(&table).unwrap();
    let loaded = palpate_kernel::table::TensorMassTable::<f32>::load(file.bytes()).unwrap();
    assert_eq!(loaded.vertex_count(), 216);
    assert_eq!(loaded.density_kg_m3(), 1000.0);
    assert!(loaded.is_fixed(0) && loaded.edge_count() > 0);

    let mesh = reference("meshes/cube.msh");
    let base = [
        "tables",
        "build",
        &mesh,
        "--young",
        "5000",
        "--poisson",
        "0.45",
        "--fix",
        "z<0.001",
        "-o",
        "/dev/null",
    ];
    let out = palpate(&[&base[..], &["--kind", "tensor-mass"]].concat());
    assert_one_line_error(&out, &["--kind tensor-mass needs --density"]);
    let out = palpate(&[&base[..], &["--density", "1000"]].concat());
    assert_one_line_error(&out, &["--density applies to --kind tensor-mass only"]);
}

/// `tables build --compress hmatrix [--tolerance REL]`: the options of the 16-bit codes refused
/// with it, `--tolerance` refused without it and outside `(0, 1)`, each in one line.
#[test]
fn hmatrix_options_are_checked() {
    let out = |extra: &[&str]| build_cube(&temp("cube-hmatrix-bad.tbl"), "5000", extra);
    let codes_only = "--drop-below and --contact-blocks apply to --compress f16|q16";
    assert_one_line_error(
        &out(&["--compress", "hmatrix", "--drop-below", "0.1"]),
        &[codes_only],
    );
    assert_one_line_error(
        &out(&["--compress", "hmatrix", "--contact-blocks", "f32"]),
        &[codes_only],
    );
    assert_one_line_error(
        &out(&["--compress", "q16", "--tolerance", "1e-4"]),
        &["--tolerance applies to --compress hmatrix"],
    );
    assert_one_line_error(
        &out(&["--compress", "hmatrix", "--tolerance", "2"]),
        &["--tolerance 2", "(0, 1)"],
    );
}

/// `tables build --compress q16 --drop-below REL`: a table about half the f32 one that
/// `tables info` reports (its flash footprint by section, the encoding and the errors measured
/// at build) and that `precomputed solve` reads; the flags' refusals, one line each.
#[test]
fn build_compressed_table_and_report_it() {
    let (f32_table, q16_table) = (temp("cube-f32.tbl"), temp("cube-q16.tbl"));
    build_cube_table(&f32_table, &[]);
    build_cube_table(&q16_table, &["--compress", "q16", "--drop-below", "0.05"]);
    let f32_len = std::fs::metadata(&f32_table).unwrap().len();
    let q16_len = std::fs::metadata(&q16_table).unwrap().len();
    // 16 of 36 bytes per block saved, 4 % of the interior blocks dropped, the rest unchanged:
    // 55.2 % of the f32 table (the uncompressed sections, mostly the collision index, are 7 %).
    assert!(q16_len * 100 < f32_len * 56, "{q16_len} vs {f32_len}");
    let info = palpate(&["tables", "info", &q16_table.display().to_string()]);
    assert!(info.status.success());
    let text = String::from_utf8_lossy(&info.stdout);
    for needle in [
        &format!("flash footprint: {q16_len} bytes"),
        "section surface-codes: 6786 x 18 bytes = 122148 bytes",
        "section interior-kept:",
        "compression: contact (surface) blocks q16, interior blocks q16, dropped below 0.05",
        "over 580 contact sets",
        "max force error",
        "validation: ok",
    ] {
        assert!(text.contains(needle), "missing '{needle}' in\n{text}");
    }
    let info = palpate(&["tables", "info", &f32_table.display().to_string()]);
    let text = String::from_utf8_lossy(&info.stdout);
    assert!(
        text.contains("section compliance-surface: 6786 x 36 bytes")
            && !text.contains("compression:"),
        "{text}"
    );
    let solve = |table: &std::path::Path| {
        let out = palpate(&[
            "precomputed",
            "solve",
            &table.display().to_string(),
            "--contact",
            "194:0,0,-0.01",
            "--json",
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        json["contact_forces"][0][2].as_f64().unwrap()
    };
    let (want, got) = (solve(&f32_table), solve(&q16_table));
    assert!((got - want).abs() <= 1e-3 * want.abs(), "{got} vs {want}");

    let out = |extra: &[&str]| build_cube(&temp("cube-bad.tbl"), "5000", extra);
    assert_one_line_error(
        &out(&["--drop-below", "0.1"]),
        &["--drop-below", "--compress"],
    );
    assert_one_line_error(
        &out(&["--contact-blocks", "f32"]),
        &["--contact-blocks", "--compress"],
    );
    assert_one_line_error(
        &out(&["--compress", "q16", "--drop-below", "1.5"]),
        &["'1.5' for '--drop-below <REL>'", "[0, 1)"],
    );
    assert_one_line_error(
        &out(&["--compress", "f16", "--precision", "f64"]),
        &["--compress applies to f32 tables"],
    );
    assert_one_line_error(
        &out(&[
            "--compress",
            "q16",
            "--kind",
            "tensor-mass",
            "--density",
            "1000",
        ]),
        &["--compress applies to --kind precomputed only"],
    );
    // An unknown code: clap's refusal, which lists the codes.
    let bad_code = out(&["--compress", "q8"]);
    let err = String::from_utf8_lossy(&bad_code.stderr);
    assert_eq!(bad_code.status.code(), Some(2), "{err}");
    assert!(err.contains("'q8'") && err.contains("f16, q16"), "{err}");
}

#[test]
fn bad_arguments_and_files_exit_2_with_one_line() {
    let mesh = reference("meshes/cube.msh");
    let out = palpate(&[
        "tables",
        "build",
        &mesh,
        "--young",
        "5000",
        "--poisson",
        "0.45",
        "--fix",
        "q<1",
        "-o",
        "/dev/null",
    ]);
    assert_one_line_error(&out, &["bad --fix predicate"]);
    let out = palpate(&[
        "tables",
        "build",
        &mesh,
        "--young",
        "5000",
        "--poisson",
        "0.6",
        "--fix",
        "z<0.001",
        "-o",
        "/dev/null",
    ]);
    assert_one_line_error(&out, &["oisson"]);
    let out = palpate(&[
        "tables",
        "build",
        &mesh,
        "--young",
        "5000",
        "--poisson",
        "0.45",
        "--fix",
        "z<-1",
        "-o",
        "/dev/null",
    ]);
    assert_one_line_error(&out, &["no vertex matches"]);
    let out = palpate(&[
        "tables",
        "build",
        "/nonexistent.msh",
        "--young",
        "5000",
        "--poisson",
        "0.45",
        "--fix",
        "z<0",
        "-o",
        "/dev/null",
    ]);
    assert_one_line_error(&out, &["nonexistent.msh"]);
    let garbage = temp("garbage.tbl");
    std::fs::write(
        &garbage,
        b"not a table at all, just some bytes that are long enough to parse a header from them ok",
    )
    .unwrap();
    let out = palpate(&["tables", "info", &garbage.display().to_string()]);
    assert_one_line_error(&out, &["failed validation"]);
    let table = temp("cube-err.tbl");
    build_cube_table(&table, &[]);
    let table_str = table.display().to_string();
    for (contact, error) in [
        ("0:0,0,-0.01", "vertex 0 is fixed"),
        ("194:0,0", "--contact '194:0,0'"),
        ("194,195,200@1,0,0:0,0,0", "wrong form"),
    ] {
        let out = palpate(&[
            "precomputed",
            "solve",
            &table_str,
            "--contact",
            contact,
            "--json",
        ]);
        assert_one_line_error(&out, &[error]);
    }
    let out = palpate(&["precomputed", "nonsense"]);
    assert_eq!(out.status.code(), Some(2));
}

fn dynamic_run(extra: &[&str]) -> Output {
    let mesh = reference("meshes/cube.msh");
    let mut args = vec![
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
        "--json",
    ];
    args.extend_from_slice(extra);
    palpate(&args)
}

#[test]
fn dynamic_run_prints_the_contract_json() {
    let out = dynamic_run(&[
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
        "--cut-tets",
        "5,6",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["displacements"].as_array().unwrap().len(), 216);
    // Pushed down at 194: it moves down; the base stays.
    assert!(json["displacements"][194][2].as_f64().unwrap() < 0.0);
    assert_eq!(json["displacements"][0][2].as_f64(), Some(0.0));
    assert!(json["kinetic_energy"].as_f64().unwrap() >= 0.0);
    assert!(json["volume_change"].as_f64().unwrap().is_finite());
    assert!(json["fault"].is_null());
    assert_eq!(json["removed_tets"], serde_json::json!([5, 6]));

    let out = dynamic_run(&[
        "--damping",
        "0",
        "--load",
        "194:0,0,-1",
        "--integrator",
        "euler",
        "--dt",
        "0.5",
        "--steps",
        "100",
    ]);
    assert!(out.status.success());
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(
        json["fault"].as_str().unwrap().contains("beyond the bound"),
        "{json}"
    );

    let out = dynamic_run(&[
        "--damping",
        "0",
        "--integrator",
        "rk4",
        "--dt",
        "0.01",
        "--steps",
        "1",
        "--cut-tets",
        "9999",
    ]);
    assert_one_line_error(&out, &["tet 9999 does not exist"]);
    let out = dynamic_run(&[
        "--damping",
        "0",
        "--integrator",
        "leapfrog",
        "--dt",
        "0.01",
        "--steps",
        "1",
    ]);
    assert_eq!(out.status.code(), Some(2));
}

/// `dynamic run --model stvk|stvk-incompressible|corotational|neo-hookean`:
/// the same JSON contract; under the same load the St Venant-Kirchhoff cube
/// moves (not the same as the linear one at this 10 % strain), every law
/// presses the loaded vertex down, and the penalty needs its γ.
#[test]
fn dynamic_run_takes_the_elastic_law() {
    let common = [
        "--damping",
        "8",
        "--load",
        "194:0,0,-3",
        "--integrator",
        "symplectic",
        "--dt",
        "0.004",
        "--steps",
        "300",
    ];
    let mut tips = Vec::new();
    for model in [
        &["--model", "linear"][..],
        &["--model", "stvk"],
        &["--model", "stvk", "--form", "tensors"],
        &["--model", "stvk-incompressible", "--incompressibility", "5"],
        &["--model", "corotational"],
        &["--model", "neo-hookean"],
    ] {
        let out = dynamic_run(&[&common[..], model].concat());
        assert!(
            out.status.success(),
            "{model:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert!(json["fault"].is_null(), "{model:?}: {json}");
        tips.push(json["displacements"][194][2].as_f64().unwrap());
    }
    println!(
        "vertex 194 z displacement, linear / StVK / StVK tensors / + penalty / co-rotational / \
         neo-Hookean: {tips:?}"
    );
    assert!(tips.iter().all(|&z| z < 0.0));
    assert_ne!(tips[0], tips[1]);
    // The two St Venant-Kirchhoff forms agree to rounding (f64).
    assert!((tips[1] - tips[2]).abs() <= 1e-12 * tips[1].abs());

    let out = dynamic_run(&[&common[..], &["--model", "stvk-incompressible"]].concat());
    assert_one_line_error(&out, &["needs --incompressibility"]);
    let out = dynamic_run(&[&common[..], &["--incompressibility", "5"]].concat());
    assert_one_line_error(&out, &["applies to --model stvk-incompressible only"]);
}

/// `stvk forces --json` on the JSON reference's first cube configuration:
/// `{"forces": [...], "energy": J}` equal to the reference within 1e-10
/// relative, both forms; a short CSV line is a one-line error naming it.
#[test]
fn stvk_forces_prints_forces_and_energy() {
    let text = std::fs::read_to_string(reference("svk/svk_cube.json")).unwrap();
    let reference_json: serde_json::Value = serde_json::from_str(&text).unwrap();
    let config = &reference_json["configs"][0];
    let csv = temp("deformed.csv");
    let lines: String = config["x"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| format!("{},{},{}\n", p[0], p[1], p[2]))
        .collect();
    std::fs::write(&csv, lines).unwrap();
    let mesh = reference("meshes/cube.msh");
    for form in ["per-tet", "tensors"] {
        let out = palpate(&[
            "stvk",
            "forces",
            &mesh,
            "--young",
            "5000",
            "--poisson",
            "0.45",
            "--deformed",
            csv.to_str().unwrap(),
            "--form",
            form,
            "--json",
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let energy = json["energy"].as_f64().unwrap();
        let expected = config["energy"].as_f64().unwrap();
        assert!(
            (energy - expected).abs() <= 1e-10 * expected,
            "{form}: {energy} vs {expected}"
        );
        let forces = json["forces"].as_array().unwrap();
        assert_eq!(forces.len(), 216);
        let f = forces[7][1].as_f64().unwrap();
        let r = config["forces"][7][1].as_f64().unwrap();
        assert!(
            (f - r).abs() <= 1e-10 * r.abs().max(1.0),
            "{form}: {f} vs {r}"
        );
    }
    let bad = temp("bad.csv");
    std::fs::write(&bad, "0,0,0\n1,2\n").unwrap();
    let out = palpate(&[
        "stvk",
        "forces",
        &mesh,
        "--young",
        "5000",
        "--poisson",
        "0.45",
        "--deformed",
        bad.to_str().unwrap(),
        "--json",
    ]);
    assert_one_line_error(&out, &["line 2"]);
}

/// `palpate budget <built-in|built-in-dynamic> --json --trajectory NAME`:
/// for both models, on both mesh sizes, every tick's callgrind instruction
/// count at or below the static bound from the table sizes and capacities
/// (needs valgrind: `tools/setup.sh` installs it). Instruction counts are
/// deterministic, so this is not a timed test. One trajectory per model:
/// `strike` (a fast oblique entry: the highest mean count per tick on the
/// pre-computed model, every trajectory sharing its largest tick, the first
/// detection) and `slide` (tracking across the deforming surface: the
/// largest tick and the most triangles tested on the dynamic model);
/// `.ci/run` runs the exhaustive `palpate budget` on every trajectory.
#[test]
fn budget_ticks_stay_within_the_static_bound() {
    for (scene, trajectory) in [("built-in", "strike"), ("built-in-dynamic", "slide")] {
        let dir = temp(&format!("budget-{scene}"));
        budget_within_bound(scene, trajectory, &dir, 900);
        if scene == "built-in" && palpate::callgrind::STARTS_INSTRUMENTATION {
            same_counts_from_the_first_tick(scene, trajectory, &dir);
        }
    }
}

/// The budget's probe (coarse mesh) left in `dir` by a `palpate budget`
/// run, measured again instrumented from the process's start and from the
/// first tick (the client request): the same count at every tick, exactly
/// (callgrind collects only the ticks either way; the second start only
/// spares the dumps the start-up's code).
fn same_counts_from_the_first_tick(scene: &str, trajectory: &str, dir: &std::path::Path) {
    use palpate::budget::{InstrumentFrom, measure_from};
    let exe = std::path::Path::new(env!("CARGO_BIN_EXE_palpate"));
    let args: Vec<String> = [
        "budget",
        scene,
        "--probe",
        dir.join("table-0.bin").to_str().unwrap(),
        dir.join(format!("{trajectory}-0.csv")).to_str().unwrap(),
        "0",
    ]
    .map(String::from)
    .to_vec();
    let counts = [InstrumentFrom::Start, InstrumentFrom::FirstTick]
        .map(|from| measure_from(exe, &args, &dir.join(format!("cg-{from:?}")), from).unwrap());
    assert!(counts[0].len() > 900, "{} ticks", counts[0].len());
    assert!(counts[0].iter().all(|&ir| ir > 0));
    assert_eq!(counts[0], counts[1]);
}

/// `palpate budget` on a hybrid scene (a 6 × 6 × 3-cell block whose
/// `[[zone]]` makes its top corner tensor-mass, the rest pre-computed):
/// every tick of the `poke` at or below the hybrid's static bound (the
/// whole surface's triangles, both solves), on both mesh sizes.
#[test]
fn budget_of_a_hybrid_scene_stays_within_the_static_bound() {
    let dir = fresh_dir("budget-hybrid");
    let scene = dir.join("hybrid.toml");
    std::fs::write(
        &scene,
        "fix = [\"z<0.0001\"]\n[generated]\nbox_m = [0.12, 0.12, 0.06]\ncells = [6, 6, 3]\n\
         [material]\nyoung_pa = 3000.0\npoisson = 0.45\n[model]\nkind = \"dynamic\"\n\
         dt_s = 0.0005\ndamping_per_s = 30.0\n[rates]\nphysics_every = 10\n[[zone]]\n\
         kind = \"cut\"\nshape = \"box\"\nmin_m = [0.08, 0.08, 0.04]\nmax_m = [0.12, 0.12, 0.06]\n\
         [partition]\nmargin_rings = 1\n",
    )
    .unwrap();
    budget_within_bound(scene.to_str().unwrap(), "poke", &dir.join("work"), 400);
}

/// Runs `palpate budget SCENE --json --trajectory TRAJECTORY` in `dir` and
/// checks its two rows (the scene's two mesh sizes): that trajectory, more
/// than `min_ticks` ticks, every tick's count positive and at most the
/// static bound.
fn budget_within_bound(scene: &str, trajectory: &str, dir: &std::path::Path, min_ticks: u64) {
    let out = palpate(&[
        "budget",
        scene,
        "--json",
        "--trajectory",
        trajectory,
        "--work-dir",
        dir.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let rows: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let rows = rows.as_array().unwrap();
    assert_eq!(rows.len(), 2, "1 trajectory x 2 meshes");
    for row in rows {
        let (max, bound) = (
            row["max_ir"].as_u64().unwrap(),
            row["bound_ir"].as_u64().unwrap(),
        );
        println!(
            "{scene}: {} on {}: {max} <= {bound}",
            row["trajectory"], row["mesh"]
        );
        assert_eq!(row["trajectory"], trajectory);
        assert!(row["ticks"].as_u64().unwrap() > min_ticks);
        assert!(max > 0 && max <= bound, "{row}");
    }
}

/// `palpate budget --trajectory` refuses a name the scene does not generate,
/// naming the ones it does, before measuring anything.
#[test]
fn budget_refuses_an_unknown_trajectory() {
    let dir = temp("budget-unknown");
    let out = palpate(&[
        "budget",
        "built-in",
        "--trajectory",
        "wobble",
        "--work-dir",
        dir.to_str().unwrap(),
    ]);
    assert_one_line_error(&out, &["--trajectory wobble"]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("strike"));
}

/// `session generate` then `session run` on both built-in scenes: the CSV
/// contract `t,fx,fy,fz,contacts,status`, one line per 1 ms tick over the
/// trajectory's 1 s, every status `ok`, contact on part of the run.
#[test]
fn session_run_drives_both_models_through_the_cli() {
    let dir = temp("session-cli");
    std::fs::create_dir_all(&dir).unwrap();
    let poke = dir.join("poke.csv");
    let out = palpate(&["session", "generate", "poke", "-o", poke.to_str().unwrap()]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for scene in ["built-in", "built-in-dynamic"] {
        let forces = dir.join(format!("{scene}.csv"));
        let out = palpate(&[
            "session",
            "run",
            scene,
            "--trajectory",
            poke.to_str().unwrap(),
            "--out",
            forces.to_str().unwrap(),
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let text = std::fs::read_to_string(&forces).unwrap();
        let mut lines = text.lines();
        assert_eq!(lines.next(), Some("t,fx,fy,fz,contacts,status"));
        let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
        assert_eq!(rows.len(), 1001, "{scene}");
        assert!(rows.iter().all(|r| r.len() == 6 && r[5] == "ok"), "{scene}");
        assert!(rows.iter().filter(|r| r[4] == "1").count() > 100, "{scene}");
    }
}

#[test]
fn session_run_refuses_a_region_absent_from_the_mesh() {
    let dir = temp("session-region");
    std::fs::create_dir_all(&dir).unwrap();
    // A 2 x 2 x 2 cm block whose tets are all of region 1 (MSH 2.2 physical tag).
    let mesh = palpate::mesh::generate::box_mesh([2, 2, 2], [0.02, 0.02, 0.02]);
    let mut msh = format!(
        "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n{}\n",
        mesh.positions.len()
    );
    for (i, p) in mesh.positions.iter().enumerate() {
        msh += &format!("{} {:?} {:?} {:?}\n", i + 1, p[0], p[1], p[2]);
    }
    msh += &format!("$EndNodes\n$Elements\n{}\n", mesh.tets.len());
    for (t, tet) in mesh.tets.iter().enumerate() {
        let [a, b, c, d] = tet.map(|v| v + 1);
        msh += &format!("{} 4 2 1 1 {a} {b} {c} {d}\n", t + 1);
    }
    msh += "$EndElements\n";
    std::fs::write(dir.join("block.msh"), msh).unwrap();
    let scene = dir.join("nodule.toml");
    std::fs::write(
        &scene,
        "mesh = \"block.msh\"\nfix = [\"z<0.001\"]\n[material]\nyoung_pa = 3000.0\npoisson = 0.45\n\
         [[region]]\nid = 9\nyoung_pa = 30000.0\npoisson = 0.45\n",
    )
    .unwrap();
    let poke = dir.join("poke.csv");
    let out = palpate(&["session", "generate", "poke", "-o", poke.to_str().unwrap()]);
    assert!(out.status.success());
    let out = palpate(&[
        "session",
        "run",
        scene.to_str().unwrap(),
        "--trajectory",
        poke.to_str().unwrap(),
        "--out",
        dir.join("forces.csv").to_str().unwrap(),
    ]);
    assert_one_line_error(
        &out,
        &["nodule.toml: [[region]] id = 9: ", "block.msh", "region 9"],
    );
}

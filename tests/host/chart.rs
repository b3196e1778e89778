//! The chart's pieces with an independent truth: the remap's command-line word round trip
//! (`chart::ticks`), the Pareto front and "cheapest within" on hand-made points
//! (`chart::select`), and the SVG text outlines against the font's own tables (`chart::svg_text`).

use palpate::chart::select::{cheapest_within, pareto_front};
use palpate::chart::svg_text::outline_text;
use palpate::chart::ticks::{parse_remap, remap_word};
use palpate_kernel::precomputed::{QuasiNonLinear, Remap};

/// The command-line word carries the remap exactly (f64 → text → f64,
/// then f32, as the tick runs it).
#[test]
fn remap_word_round_trips() {
    let c = [0.9, 0.5, -0.1, 0.0, 0.0];
    let q = QuasiNonLinear {
        radial: Remap::new(c, 0.01).unwrap(),
        force: Remap::new([1.2, 3.0, 0.0, 0.0, 0.0], 2.5).unwrap(),
    };
    let back = parse_remap(&remap_word(Some(&q))).unwrap().unwrap();
    assert_eq!(back.radial.coefficients(), &c.map(|x| x as f32));
    assert_eq!(back.radial.x_max(), 0.01f32);
    assert_eq!(back.force.coefficients()[1], 3.0f32);
    assert_eq!(back.force.x_max(), 2.5f32);
    assert!(parse_remap("linear").unwrap().is_none());
    assert!(parse_remap("1,2").is_err());
}

/// Hand-made points: (1, 0.5) and (2, 0.1) and (4, 0.01) are each
/// best at their cost; (3, 0.2) is dominated by (2, 0.1); (5, 0.01)
/// by (4, 0.01) (costlier, no better); (0.5, NaN) has no error and is
/// off the front without dominating anything; the duplicate of (2, 0.1)
/// stays on it.
#[test]
fn pareto_front_of_hand_made_points() {
    let points = [
        (1.0, 0.5),
        (3.0, 0.2),
        (2.0, 0.1),
        (4.0, 0.01),
        (5.0, 0.01),
        (0.5, f64::NAN),
        (2.0, 0.1),
    ];
    assert_eq!(
        pareto_front(&points),
        [true, false, true, true, false, false, true]
    );
}

/// Within 20 %: (1, 0.15) is cheapest; within 5 %: (2, 0.04) beats the
/// costlier (4, 0.001); within 0.05 %: none; the bound is inclusive;
/// equal costs give the first.
#[test]
fn cheapest_within_bounds() {
    let points = [(4.0, 0.001), (1.0, 0.15), (2.0, 0.04), (2.0, 0.03)];
    assert_eq!(cheapest_within(&points, 0.20), Some(1));
    assert_eq!(cheapest_within(&points, 0.05), Some(2));
    assert_eq!(cheapest_within(&points, 0.15), Some(1));
    assert_eq!(cheapest_within(&points, 0.002), Some(0));
    assert_eq!(cheapest_within(&points, 0.0005), None);
    assert_eq!(cheapest_within(&[(1.0, f64::NAN)], 1.0), None);
}

static FONT: &[u8] = include_bytes!("../../host-harness/assets/fonts/DejaVuSans.ttf");

/// The x extent (min, max) of the coordinates of a path's `d`.
fn x_extent(svg: &str) -> (f64, f64) {
    let d = svg
        .split_once(" d=\"")
        .and_then(|(_, rest)| rest.split_once('"'))
        .map(|(d, _)| d)
        .unwrap();
    let numbers: Vec<f64> = d
        .split(|c: char| c.is_ascii_alphabetic() || c == ' ')
        .filter(|s| !s.is_empty())
        .map(|s| s.parse().unwrap())
        .collect();
    numbers
        .chunks_exact(2)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p[0]), hi.max(p[0]))
        })
}

/// A plotters `<text>` becomes one `<path>` with the same fill,
/// opacity and rotation and no font reference; the rest of the SVG is
/// kept. DejaVu Sans' `H` (2048 units per em; advance 1540, outline
/// x 201…1339: its `hmtx` and `glyf` entries, read from the TTF's tables
/// by a separate parser) at font size 20.48 (0.01 px per unit) spans
/// x = 10 + 2.01 … 10 + 13.39 anchored at its start, and 7.70 (half
/// its advance) less anchored in the middle.
#[test]
fn text_becomes_outlines() {
    let svg = "<svg>\n<rect/>\n<text x=\"10\" y=\"40\" dy=\"0.76em\" text-anchor=\"start\" \
               font-family=\"sans-serif\" font-size=\"20.48\" opacity=\"0.5\" \
               fill=\"#FF0000\" transform=\"rotate(270, 10, 40)\">\nH\n</text>\n</svg>\n";
    let out = outline_text(svg, FONT).unwrap();
    assert!(
        !out.contains("<text") && !out.contains("font-family"),
        "{out}"
    );
    assert!(out.starts_with("<svg>\n<rect/>\n<path d=\"M"), "{out}");
    assert!(out.ends_with("/>\n</svg>\n"), "{out}");
    assert!(out.contains("fill=\"#FF0000\" opacity=\"0.5\" transform=\"rotate(270, 10, 40)\""));
    let (lo, hi) = x_extent(&out);
    assert!(
        (lo - 12.01).abs() < 0.006 && (hi - 23.39).abs() < 0.006,
        "{lo} {hi}"
    );
    let middle = outline_text(&svg.replace("\"start\"", "\"middle\""), FONT).unwrap();
    let (lo, hi) = x_extent(&middle);
    assert!(
        (lo - 4.31).abs() < 0.006 && (hi - 15.69).abs() < 0.006,
        "{lo} {hi}"
    );
}

/// Escaped text is unescaped before layout: `&lt;` is one `<` glyph
/// (outline x 217…1499 units, the font's `glyf` entry) and a space has
/// no outline but advances 651 units (`hmtx`); at font size 10.24
/// (0.005 px per unit) that is x 1.085…7.495, then 3.255 further right
/// behind a space.
#[test]
fn escaped_text_and_spaces() {
    let text = |s: &str| {
        format!(
            "<text x=\"0\" y=\"0\" dy=\"0.5ex\" text-anchor=\"start\" font-family=\"a\" \
             font-size=\"10.24\" opacity=\"1\" fill=\"#000000\">\n{s}\n</text>\n"
        )
    };
    let (lo, hi) = x_extent(&outline_text(&text("&lt;"), FONT).unwrap());
    assert!(
        (lo - 1.085).abs() < 0.006 && (hi - 7.495).abs() < 0.006,
        "{lo} {hi}"
    );
    let (lo, hi) = x_extent(&outline_text(&text(" &lt;"), FONT).unwrap());
    assert!(
        (lo - 4.34).abs() < 0.006 && (hi - 10.75).abs() < 0.006,
        "{lo} {hi}"
    );
}

/// Every table of the memory chart (full and `--quick`) is one `palpate
/// tables build` can make, and its stated flags are its options: each
/// encoding's compression passes the build's own check, its flags read
/// back (`--compress CODE`, `--drop-below REL`, `--contact-blocks dropped`,
/// `--tolerance REL`) to the same code, threshold, touchable blocks and
/// tolerance, and no two tables of a chart share flags. Each chart mesh
/// has fixed and free vertices (the full chart's finer organ: the
/// documented 1386 vertices).
#[test]
fn memory_chart_tables_are_the_stated_builds() {
    use palpate::chart::memory::{
        Encoding, FULL_ENCODINGS, FULL_MESHES, QUICK_ENCODINGS, QUICK_MESHES,
    };
    use palpate::table::compress::{BlockCode, ContactBlocks};
    let read_back = |flags: &str| {
        let words: Vec<&str> = flags.split(' ').collect();
        let value = |name: &str| words.iter().position(|w| *w == name).map(|i| words[i + 1]);
        let number = |name: &str| value(name).map_or(0.0, |v| v.parse::<f64>().unwrap());
        let code = value("--compress").map(|c| match c {
            "f16" => BlockCode::F16,
            "q16" => BlockCode::Q16,
            "hmatrix" => BlockCode::Hmatrix,
            "hmatrix-q16" => BlockCode::HmatrixQ16,
            other => panic!("{other}"),
        });
        let contact = match value("--contact-blocks") {
            Some("dropped") => ContactBlocks::Dropped,
            None => ContactBlocks::Coded,
            Some(other) => panic!("{other}"),
        };
        (code, number("--drop-below"), contact, number("--tolerance"))
    };
    for encodings in [&FULL_ENCODINGS[..], &QUICK_ENCODINGS[..]] {
        let mut seen: Vec<String> = Vec::new();
        for &encoding in encodings {
            let flags = encoding.flags();
            assert!(!seen.contains(&flags), "{flags}");
            let (code, drop_below, contact, tolerance) = read_back(&flags);
            match encoding.compression() {
                None => {
                    assert_eq!(encoding, Encoding::Dense);
                    assert_eq!(flags, "(none)");
                }
                Some(c) => {
                    c.check().unwrap();
                    assert_eq!(Some(c.code), code, "{flags}");
                    assert_eq!(c.drop_below, drop_below, "{flags}");
                    assert_eq!(c.contact, contact, "{flags}");
                    if c.code.is_hierarchical() {
                        assert_eq!(c.tolerance, tolerance, "{flags}");
                        assert_eq!(encoding.parameter(), Some(tolerance), "{flags}");
                    }
                }
            }
            seen.push(flags);
        }
    }
    for mesh in FULL_MESHES.iter().chain(&QUICK_MESHES) {
        let loaded = mesh.load().unwrap();
        let fixed = palpate::fix::fixed_vertices(&loaded.mesh.positions, &loaded.fix, &[]).0;
        let free = fixed.iter().filter(|&&f| !f).count();
        assert!(free > 0 && free < fixed.len(), "{}", loaded.label);
    }
    let finer = FULL_MESHES[1].load().unwrap();
    assert_eq!(finer.mesh.positions.len(), 1386);
}

/// The consistent face loads (`Body::loads`): the press's nodal loads sum
/// to its total force (with the lateral imperfection), the twist's to no
/// force and a torque of the magnitude about the axis, to rounding (1e-12
/// relative: sums of some 100 terms of the load's size).
#[test]
fn face_loads_carry_the_total_force_and_torque() {
    use nalgebra::Vector3;
    use palpate::chart::{Body, Load, PRESS_IMPERFECTION};
    let body = Body::cylinder((2, 10), palpate::experiment::scenes::tissue());
    assert_eq!(body.faces.len(), 32, "the top face's triangles");
    let sum = |f: &[[f64; 3]]| f.iter().map(|x| Vector3::from(*x)).sum::<Vector3<f64>>();
    let press = sum(&body.loads(Load::Press, 2.0));
    assert!((press - Vector3::new(2.0 * PRESS_IMPERFECTION, 0.0, -2.0)).norm() < 1e-12);
    let twist = body.loads(Load::Twist, 3.0);
    assert!(sum(&twist).norm() < 1e-12);
    let torque: f64 = twist
        .iter()
        .zip(&body.mesh.positions)
        .map(|(f, p)| {
            (Vector3::from(*p) - body.centre)
                .cross(&Vector3::from(*f))
                .z
        })
        .sum();
    assert!((torque - 3.0).abs() < 1e-12, "{torque}");
}

/// The truth's red refinement keeps the geometry: every tet positively
/// oriented, the volume the same to rounding, one new vertex per edge.
#[test]
fn refinement_keeps_the_volume() {
    use palpate::chart::{Body, truth::refine};
    let body = Body::cylinder((1, 5), palpate::experiment::scenes::tissue());
    let volume = |p: &[[f64; 3]], t: &[[u32; 4]]| -> Vec<f64> {
        t.iter()
            .map(|t| {
                let [a, b, c, d] = t.map(|v| nalgebra::Vector3::from(p[v as usize]));
                (b - a).cross(&(c - a)).dot(&(d - a)) / 6.0
            })
            .collect()
    };
    let (p, t, flags) = refine(
        &body.mesh.positions,
        &body.mesh.tets,
        core::slice::from_ref(&body.fixed),
    );
    assert_eq!(t.len(), 8 * body.mesh.tets.len());
    let fine = volume(&p, &t);
    assert!(fine.iter().all(|&v| v > 0.0));
    let coarse: f64 = volume(&body.mesh.positions, &body.mesh.tets).iter().sum();
    assert!((fine.iter().sum::<f64>() - coarse).abs() < 1e-14 * coarse.abs().max(1e-300) * 1e3);
    // The base's midpoints are fixed too: (2·1+1)² vertices on the base
    // of the coarse mesh, (4+1)² on the refined one.
    assert_eq!(flags[0].iter().filter(|&&f| f).count(), 25);
}

/// The neo-Hookean truth against beam theory: under the small bend (the
/// chart's 1 % level, linear regime) its P2 level on the 2x10 cylinder
/// deflects as a Timoshenko cantilever, `δ = F L³/(3EI) + F L/(κGA)` with
/// the circle's `I` and `A` and `κ = 0.9`: measured 1.4656 mm against
/// 1.4679 mm. Bound 6 %: the section is a 16-gon (5 % less `I` than the
/// circle) and the fixed base stiffens the beam, by a few % each way. Its
/// P1 level on the same mesh is 32 % stiffer (measured 1.0000 mm: linear
/// tets lock in bending), the discretization error the chart's models
/// share and the St Venant-Kirchhoff reference on the same mesh hides.
#[test]
fn truth_bends_as_a_timoshenko_beam() {
    use palpate::chart::truth::{Discretization, truth};
    use palpate::chart::{Body, HEIGHT_M, Load};
    let material = palpate::experiment::scenes::tissue();
    let body = Body::cylinder((2, 10), material);
    let force = 0.01 * HEIGHT_M / body.tip_per_newton_m(Load::Bend).unwrap();
    let levels = [Discretization::p1(0), Discretization::p2(0)];
    let t = truth(&body, &levels, Load::Bend, 0.01, force);
    let (p1, p2) = (t.levels[0].tip_m, t.levels[1].tip_m);
    let (e, nu, l, r) = (
        material.young_pa,
        material.poisson,
        HEIGHT_M,
        HEIGHT_M / 5.0,
    );
    let (area, inertia) = (
        core::f64::consts::PI * r * r,
        core::f64::consts::PI * r.powi(4) / 4.0,
    );
    let shear = e / (2.0 * (1.0 + nu));
    let beam = force * (l.powi(3) / (3.0 * e * inertia) + l / (0.9 * shear * area));
    assert!((p2 / beam - 1.0).abs() < 0.06, "P2 {p2} against {beam}");
    assert!(p1 / p2 < 0.75, "P1 {p1} P2 {p2}");
    assert_eq!(t.tip_m, p2);
    assert!((t.change.unwrap() - (p2 - p1).abs() / p2).abs() < 1e-15);
}

/// A truth is scored against only where it converged: its verdict is
/// `converged` at a change of at most `CONVERGED` (1e-3) between its two
/// finest levels, and `no converged truth` with the change above it, or with
/// the finest failed level's fault (the P2 solve's refusal of a fold) when
/// a level has no quantity.
#[test]
fn truth_verdict_needs_convergence() {
    use palpate::chart::Load;
    use palpate::chart::truth::{CONVERGED, Discretization, Truth, TruthLevel};
    let level = |tip_m: f64, fault: Option<&str>| TruthLevel {
        label: "P2 on 2x10 ×1".into(),
        discretization: Discretization::p2(0),
        nodes: 1701,
        tets: 960,
        iterations: 4,
        seconds: 1.0,
        tip_m,
        fault: fault.map(Into::into),
    };
    let truth = |tips: [f64; 2], fault: Option<&str>| Truth {
        load: Load::Bend,
        level: 0.01,
        magnitude: 1.0,
        levels: vec![level(tips[0], None), level(tips[1], fault)],
        tip_m: tips[1],
        change: (tips[0].is_finite() && tips[1].is_finite())
            .then(|| (tips[1] - tips[0]).abs() / tips[1].abs()),
    };
    let close = truth([1.0, 1.0 + 0.9 * CONVERGED], None);
    assert!(close.converged());
    assert_eq!(close.verdict(), "converged");
    let far = truth([1.0, 1.0 + 2.0 * CONVERGED], None);
    assert!(!far.converged());
    assert!(
        far.verdict()
            .starts_with("no converged truth: change 2.00e-3"),
        "{}",
        far.verdict()
    );
    let folded = truth([1.0, f64::NAN], Some("the equilibrium found folds tet 7"));
    assert!(!folded.converged());
    assert_eq!(
        folded.verdict(),
        "no converged truth: the equilibrium found folds tet 7"
    );
}

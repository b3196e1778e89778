//! The volume experiment (`palpate::experiment`, Picinbono 2001 table 2) on
//! a small cylinder: the ordering linear ≫ St Venant-Kirchhoff > St
//! Venant-Kirchhoff + incompressibility at every stage, and the dynamic
//! relaxation's linear equilibrium against the direct sparse solve; the
//! paper's protocol (loads F, 2F, 3F) against the linear model's linearity,
//! with the co-rotational and neo-Hookean laws far below the linear one.

use palpate::experiment::scenes::cylinder;
use palpate::experiment::volume_bend::{Controls, Protocol, run_scene};
use palpate::fem::material::TetMaterials;
use palpate::fem::static_solve::solve_loaded;
use palpate::tensor_mass::run::volume_change;

/// A 2 × 2 × 8-cell cylinder (768 tets). At every stage the full
/// non-linear model reaches its tilt (within the search tolerance, 0.25°)
/// and keeps every tet upright, and the order of table 2 holds: |ΔV| of the
/// linear model ≥ 5 × that of St Venant-Kirchhoff (measured ≥ 26×), which
/// is larger than with the penalty. Plain St Venant-Kirchhoff is upright at
/// 30° and has collapsed (inverted tets) by 75°, which the penalty prevents
/// (Picinbono 2001 §3.2).
#[test]
fn volume_changes_are_ordered_as_in_table_2() {
    let scene = cylinder(2, 8);
    let result = run_scene(&scene, Protocol::Tilt, &Controls::default(), |line| {
        println!("{line}")
    })
    .expect("run");
    for stage in &result.stages {
        let linear = stage.linear.volume_change.abs();
        let stvk = stage.stvk.volume_change.abs();
        let incompressible = stage.stvk_incompressible.volume_change.abs();
        println!(
            "tilt {:.0}°: linear {:.3} %, StVK {:.3} % ({} inverted), StVK+inc {:.3} %",
            stage.target,
            100.0 * linear,
            100.0 * stvk,
            stage.stvk.inverted_tets,
            100.0 * incompressible
        );
        let full = &stage.stvk_incompressible;
        assert!(full.fault.is_none() && full.inverted_tets == 0);
        assert!((full.measure - stage.target).abs() <= 0.25);
        assert!(
            linear >= 5.0 * incompressible,
            "linear {linear} vs {incompressible}"
        );
        if stage.stvk.fault.is_none() && stage.stvk.inverted_tets == 0 {
            assert!(linear >= 5.0 * stvk, "linear {linear} vs StVK {stvk}");
            assert!(stvk > incompressible, "StVK {stvk} vs {incompressible}");
        }
    }
    let first = &result.stages[0].stvk;
    let last = &result.stages[2].stvk;
    assert!(
        first.fault.is_none() && first.inverted_tets == 0,
        "StVK upright at 30°"
    );
    assert!(last.inverted_tets > 0, "plain StVK collapses by 75°");
}

/// The paper's protocol on the same cylinder. Independent truth: the
/// linear FEM equilibrium under `F`, `u_F`, by the direct sparse solve; the
/// linear model's equilibrium under `kF` is `k u_F`, so its volume change at
/// each stage must be that of `k u_F`, and 7 % at `F`. Tolerance 3e-3
/// relative: each relaxation stops at a residual of 1e-3 of the load per
/// vertex, so its displacement is within about 1e-3 (relative) of the
/// equilibrium and the volume change, dominated by its quadratic term,
/// within about 2e-3 (measured 1.9e-3, 1.4e-3, 0.9e-3; `F` itself comes
/// from a relaxed probe and carries the same error). The non-linear models
/// stay at least 5× below the linear one at every load, as in the paper
/// (7 / 28 / 63 % against 0.3 / 1 / 2 % and 0.2 / 0.5 / 1 %); so do the
/// co-rotational and neo-Hookean laws, rotation-invariant like St
/// Venant-Kirchhoff (measured −0.11 / −0.35 / −0.62 % and +0.04 / +0.15 /
/// +0.31 %), upright and relaxed without a fault.
#[test]
fn paper_loads_give_the_linear_model_seven_percent_at_f() {
    let scene = cylinder(2, 8);
    let result = run_scene(&scene, Protocol::PaperLoads, &Controls::default(), |line| {
        println!("{line}")
    })
    .expect("run");
    assert_eq!(result.stages.len(), 3);
    let unit_n = result.stages[0].force_n;
    let share = scene.direction * (unit_n / scene.loaded.len() as f64);
    let mut loads = vec![[0.0; 3]; scene.mesh.positions.len()];
    for &v in &scene.loaded {
        loads[v as usize] = share.into();
    }
    let materials = TetMaterials::uniform(scene.material, scene.mesh.tets.len());
    let (u_f, _) = solve_loaded(
        &scene.mesh.positions,
        &scene.mesh.tets,
        &materials,
        &scene.fixed,
        &[],
        &loads,
    )
    .expect("direct solve");
    let alive = vec![true; scene.mesh.tets.len()];
    for stage in &result.stages {
        let k = stage.target;
        let scaled: Vec<[f64; 3]> = u_f.iter().map(|d| d.map(|x| k * x)).collect();
        let expected = 100.0 * volume_change(&scene.mesh, &scaled, &alive);
        let linear = 100.0 * stage.linear.volume_change;
        let stvk = 100.0 * stage.stvk.volume_change;
        let incompressible = 100.0 * stage.stvk_incompressible.volume_change;
        println!(
            "{k}F = {:.4e} N: linear {linear:+.3} % (direct solve {expected:+.3} %), \
             StVK {stvk:+.3} % ({} inverted), StVK+inc {incompressible:+.3} %",
            stage.force_n, stage.stvk.inverted_tets
        );
        assert!((stage.force_n - k * unit_n).abs() <= 1e-12 * stage.force_n);
        assert!(
            (linear - expected).abs() <= 3e-3 * expected.abs(),
            "{linear} vs {expected}"
        );
        assert!(linear.abs() >= 5.0 * incompressible.abs());
        for (name, e) in [
            ("co-rotational", &stage.corotational),
            ("neo-Hookean", &stage.neo_hookean),
        ] {
            let change = 100.0 * e.volume_change;
            println!("{k}F: {name} {change:+.3} %");
            assert!(e.fault.is_none() && e.inverted_tets == 0, "{name}: {e:?}");
            assert!(linear.abs() >= 5.0 * change.abs(), "{name} {change}");
        }
    }
    assert!((100.0 * result.stages[0].linear.volume_change - 7.0).abs() <= 3e-3 * 7.0);
}

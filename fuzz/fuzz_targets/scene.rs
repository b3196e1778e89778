//! Scene TOML parser, `Scene::from_toml_str` (invalid UTF-8 replaced). No input panics; an
//! error names the source; an accepted scene validates again and its derived quantities (tick,
//! physics period, dynamic sub-steps, material) are usable; its tool has one kind per tool
//! point within the kernel's tool points, a unit jaw axis and a blade of length in
//! `(0, MAX_BLADE_M]`; its cutting and tearing capacities are in range, and tearing has a
//! criterion and a dynamic model.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use palpate::scene::{MAX_BLADE_M, MAX_CAPACITY_TETS, MAX_TOOL_POINTS, ModelSpec, Scene};

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let scene = match Scene::from_toml_str(&text, Path::new("/fuzz-scenes")) {
        Ok(scene) => scene,
        Err(err) => {
            assert!(err.to_string().starts_with("inline scene"), "{err}");
            return;
        }
    };
    if let Err(err) = scene.validate() {
        panic!("an accepted scene does not validate: {err}");
    }
    let tool = &scene.tool;
    assert!((1..=MAX_TOOL_POINTS).contains(&tool.points));
    assert_eq!(tool.kinds.len(), tool.points, "{:?}", tool.kinds);
    assert!(
        tool.kernel_points() <= MAX_TOOL_POINTS,
        "{} kernel tool points",
        tool.kernel_points()
    );
    let norm = |a: [f64; 3]| a.iter().map(|x| x * x).sum::<f64>().sqrt();
    let axis = norm(tool.jaw_axis);
    assert!(
        (axis - 1.0).abs() <= 1e-12,
        "jaw axis {:?}: {axis}",
        tool.jaw_axis
    );
    // Measured scaled, as the scene measures it: squares of small components underflow.
    let scale = tool.blade_m.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let blade = scale * norm(tool.blade_m.map(|x| x / scale));
    assert!(
        blade > 0.0 && blade <= MAX_BLADE_M,
        "blade {:?}: {blade}",
        tool.blade_m
    );
    assert!(tool.grip_opening_m.is_finite() && tool.grip_opening_m > 0.0);
    let capacities = 1..=MAX_CAPACITY_TETS;
    assert!(capacities.contains(&scene.cutting.capacity_tets));
    if let Some(tearing) = &scene.tearing {
        assert!(matches!(scene.model, ModelSpec::Dynamic(_)));
        assert!(capacities.contains(&tearing.capacity_tets));
        let criteria = [
            tearing.volume_change,
            tearing.mean_elongation,
            tearing.max_elongation,
        ];
        assert!(criteria.iter().any(Option::is_some));
        assert!(criteria.iter().flatten().all(|x| x.is_finite() && *x > 0.0));
    }
    let (tick, period) = (scene.tick_s(), scene.physics_period_s());
    assert!(tick.is_finite() && tick > 0.0, "tick {tick} s");
    assert!(
        period.is_finite() && period >= tick,
        "physics period {period} s"
    );
    assert!(scene.material.elastic.check().is_ok());
    match scene.model {
        ModelSpec::Precomputed => {
            assert!(scene.dynamic_substeps().is_none());
            assert!(!scene.fix.is_empty());
        }
        ModelSpec::Dynamic(_) => {
            let n = scene
                .dynamic_substeps()
                .expect("a dynamic scene has sub-steps");
            assert!(n >= 1);
        }
    }
});

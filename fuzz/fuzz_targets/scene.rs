//! Scene TOML parser, `Scene::from_toml_str` (invalid UTF-8 replaced). No input panics; an
//! error names the source; an accepted scene validates again and its derived quantities (tick,
//! physics period, dynamic sub-steps, material) are usable.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use palpate::session::{MAX_TOOL_POINTS, ModelSpec, Scene};

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
    assert!((1..=MAX_TOOL_POINTS).contains(&scene.tool.points));
    let (tick, period) = (scene.tick_s(), scene.physics_period_s());
    assert!(tick.is_finite() && tick > 0.0, "tick {tick} s");
    assert!(
        period.is_finite() && period >= tick,
        "physics period {period} s"
    );
    assert!(scene.elastic_material().is_ok());
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

//! Tick recordings (`palpate_script::ticks`): what `palpate budget --record`
//! writes for the Cortex-M4F cycle count (`tools/cycles-check.sh`). Every
//! setting and tool input read back bit for bit; every malformed recording
//! refused with its reason; and a recording of the built-in scene with four
//! probes, replayed on the host's kernel from the recording alone, prints
//! exactly the host's lines (what the target must print), with four
//! simultaneous contacts.

use nalgebra::Vector3;
use palpate::budget::{RECORD_BOUNDS, RECORD_RUNS, RECORD_TABLE, record};
use palpate::scene::Scene;
use palpate::scene::{DEFAULT_TOOL_RADIUS_M, ToolSpec};
use palpate::table::compress::{BlockCode, Compression, ContactBlocks};
use palpate_kernel::PrecomputedTable;
use palpate_kernel::haptic::{LoopConfig, PrecomputedLoop, SafetyLimits, ToolAction, ToolInput};
use palpate_kernel::precomputed::PrecomputedTissue;
use palpate_kernel::tensor_mass::{
    DynamicParams, ElasticLaw, Extrapolation, Integrator, PhysicsConfig, StvkForm, TearThresholds,
    Tearing,
};
use palpate_script::ticks::{
    HEADER_WORDS, Header, MAGIC, Recording, RecordingError, Settings, TOOL_WORDS, tool_words,
    write_tick,
};

fn bytes(header: &Header, tools: &[ToolInput<f32>]) -> Vec<u8> {
    header
        .words()
        .into_iter()
        .chain(tools.iter().flat_map(tool_words))
        .flat_map(u32::to_le_bytes)
        .collect()
}

fn loop_config() -> LoopConfig<f32> {
    LoopConfig {
        radius_m: 0.002,
        dt_s: 1e-3,
        limits: SafetyLimits {
            max_force_n: 4.0,
            max_slew_n_per_s: 2000.0,
        },
    }
}

/// Settings with every optional part present and values that are not
/// round numbers (a lost bit would show).
fn dynamic_settings() -> Settings {
    let params = DynamicParams::linear(30.0f32, 0.134_164_08)
        .with_law(ElasticLaw::StVenantKirchhoff(StvkForm::Tensors))
        .with_incompressibility(Some(0.37));
    let physics = PhysicsConfig {
        extrapolation: Extrapolation::Instantaneous,
        integrator: Integrator::CentralDifference,
        dt_s: 4.999_999_9e-4,
        substeps: 20,
        cut_capacity_tets: 8,
        cut_force_n: 0.2,
        tearing: Some(Tearing {
            thresholds: TearThresholds {
                volume_change: None,
                mean_elongation: Some(0.4),
                max_elongation: Some(1.0),
            },
            capacity_tets: 7,
        }),
    };
    Settings {
        loop_config: loop_config(),
        dynamic: Some((params, physics)),
    }
}

#[test]
fn a_recording_reads_back_bit_for_bit() {
    let tools = [
        ToolInput::touch(Vector3::new(0.06f32, 0.08, 0.065)),
        ToolInput {
            position_m: Vector3::new(-1e-7, f32::MAX, 0.0),
            action: ToolAction::Grip,
        },
        ToolInput {
            position_m: Vector3::new(0.03, 0.06, 0.07),
            action: ToolAction::Cut {
                blade_m: Vector3::new(0.0, 1e-3, -0.01),
            },
        },
        ToolInput::touch(Vector3::new(f32::NAN, 0.0, -0.0)),
    ];
    for settings in [
        dynamic_settings(),
        Settings {
            loop_config: loop_config(),
            dynamic: None,
        },
    ] {
        let header = Header {
            points: 2,
            ticks: 2,
            physics_every: 10,
            settings,
        };
        let bytes = bytes(&header, &tools);
        assert_eq!(bytes.len(), 4 * (HEADER_WORDS + 4 * TOOL_WORDS));
        let recording = Recording::parse(&bytes).unwrap();
        assert_eq!(*recording.header(), header);
        for k in 0..2 {
            let tick = recording.tick::<2>(k).unwrap();
            for (got, want) in tick.iter().zip(&tools[2 * k..]) {
                // Bit for bit (NaN and -0 included): compare the words.
                assert_eq!(tool_words(got), tool_words(want));
            }
        }
        assert_eq!(recording.tick::<2>(2), None, "past the last tick");
        assert_eq!(recording.tick::<3>(0), None, "another point count");
    }
}

#[test]
fn a_malformed_recording_is_refused_with_its_reason() {
    let header = Header {
        points: 1,
        ticks: 1,
        physics_every: 0,
        settings: dynamic_settings(),
    };
    let good = bytes(&header, &[ToolInput::touch(Vector3::zeros())]);
    let with_word = |i: usize, w: u32| {
        let mut b = good.clone();
        b[4 * i..4 * i + 4].copy_from_slice(&w.to_le_bytes());
        b
    };
    let cases = [
        (good[..40].to_vec(), RecordingError::NotARecording),
        (with_word(0, MAGIC + 1), RecordingError::NotARecording),
        (with_word(1, 2), RecordingError::Version(2)),
        (with_word(2, 0), RecordingError::Points(0)),
        (with_word(2, 5), RecordingError::Points(5)),
        // The dynamic flag, then the law.
        (with_word(9, 2), RecordingError::Code(9)),
        (with_word(10, 5), RecordingError::Code(10)),
        (
            good[..good.len() - 4].to_vec(),
            RecordingError::Length {
                expected: good.len(),
                found: good.len() - 4,
            },
        ),
        (with_word(HEADER_WORDS + 3, 3), RecordingError::Action(0)),
    ];
    for (bytes, error) in cases {
        assert_eq!(Recording::parse(&bytes).err(), Some(error), "{error}");
    }
}

/// `palpate budget --record` on the built-in scene with four probes (the
/// press-hold, each probe on its site): the recording, replayed on the
/// host's kernel through the loop its header describes, prints the recorded
/// host lines exactly; the probes make four simultaneous contacts. The same
/// with the table compressed (`--compress q16`, what `tools/cycles-check.sh
/// --compress q16` counts): the recorded table is the compressed one.
#[test]
fn a_recorded_press_with_four_probes_replays_to_the_host_lines() {
    let q16 = Compression {
        code: BlockCode::Q16,
        drop_below: 0.0,
        contact: ContactBlocks::Coded,
        tolerance: palpate::table::hmatrix::DEFAULT_TOLERANCE,
    };
    for (name, compression) in [
        ("record-built-in-4", None),
        ("record-built-in-4-q16", Some(q16)),
    ] {
        replays_to_the_host_lines(name, compression);
    }
}

fn replays_to_the_host_lines(dir_name: &str, compression: Option<Compression>) {
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(dir_name);
    let _ = std::fs::remove_dir_all(&dir);
    let mut scene = Scene::built_in();
    scene.tool = ToolSpec::probes(4, DEFAULT_TOOL_RADIUS_M);
    let runs = record(&scene, &dir, &["press-hold".to_string()], compression).unwrap();
    assert_eq!(runs.len(), 1);
    let list = std::fs::read_to_string(dir.join(RECORD_RUNS)).unwrap();
    let [name, ticks, bound] = list.split_whitespace().collect::<Vec<_>>()[..] else {
        panic!("{list}");
    };
    assert_eq!(name, "press-hold");
    let table_bytes = std::fs::read(dir.join(RECORD_TABLE)).unwrap();
    let table = PrecomputedTable::<f32>::load(&table_bytes).unwrap();
    assert_eq!(table.compression().is_some(), compression.is_some());
    let recorded = std::fs::read(dir.join("press-hold.ticks")).unwrap();
    let recording = Recording::parse(&recorded).unwrap();
    let header = *recording.header();
    assert_eq!(header.points, 4);
    assert_eq!(header.ticks.to_string(), ticks);
    assert_eq!(
        header.physics_every, 0,
        "no physics on the pre-computed model"
    );
    assert!(bound.parse::<u64>().unwrap() > 0);
    // The bounds: the runs' bound, then the one at 5 wait states (every unit
    // cost larger there, so the bound too).
    let bounds = std::fs::read_to_string(dir.join(RECORD_BOUNDS)).unwrap();
    let [at_zero, at_wait_states] = bounds.split_whitespace().collect::<Vec<_>>()[..] else {
        panic!("{bounds}");
    };
    assert_eq!(at_zero, bound);
    assert!(at_wait_states.parse::<u64>().unwrap() > bound.parse::<u64>().unwrap());
    let mut haptic = PrecomputedLoop::<f32, 4, 4>::new(
        PrecomputedTissue::new(&table),
        header.settings.loop_config,
    )
    .unwrap();
    let mut lines = String::new();
    let mut most = 0;
    for k in 0..header.ticks {
        let output = haptic.tick_tools(&recording.tick::<4>(k).unwrap());
        most = most.max(output.contacts);
        write_tick(&mut lines, k, &output, haptic.counters()).unwrap();
    }
    let expected = std::fs::read_to_string(dir.join("press-hold.expected")).unwrap();
    assert_eq!(lines, expected);
    assert_eq!(most, 4);
}

/// `--compress` is the pre-computed model's: a dynamic scene refuses it,
/// naming the scene.
#[test]
fn a_compressed_recording_of_a_dynamic_scene_is_refused() {
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("record-dynamic-q16");
    let scene = Scene::named("built-in-dynamic").unwrap();
    let q16 = Compression {
        code: BlockCode::Q16,
        drop_below: 0.0,
        contact: ContactBlocks::Coded,
        tolerance: palpate::table::hmatrix::DEFAULT_TOLERANCE,
    };
    let error = record(&scene, &dir, &["poke".to_string()], Some(q16)).unwrap_err();
    assert!(
        error
            .to_string()
            .contains("--compress applies to a pre-computed scene"),
        "{error:#}"
    );
}

//! The pre-computed haptic loop through the C ABI
//! (`ffi/src/precomputed_loop.rs`, `haptic.rs`): with two tool points (the
//! ABI's loop is built for four and parks the other two outside the mesh)
//! it gives bit for bit the kernel's own two-point loop, tick after tick:
//! pressing, sliding, a blade on a tissue that cannot be cut, a latched
//! fault, the reset, the release; and the same displacement field.

use palpate_ffi::haptic::{
    Force, LoopConfig, OutputStatus, Tool, ToolAction, palpate_loop_config_default,
};
use palpate_ffi::precomputed_loop::{
    PrecomputedLoop, palpate_precomputed_loop_create, palpate_precomputed_loop_displacements,
    palpate_precomputed_loop_reset, palpate_precomputed_loop_tick,
};
use palpate_ffi::status::Status;
use palpate_kernel::haptic::{
    LoopConfig as KernelConfig, PrecomputedLoop as KernelLoop, SafetyLimits, ToolAction as Action,
    ToolInput,
};
use palpate_kernel::precomputed::PrecomputedTissue;
use palpate_kernel::{PrecomputedModel, PrecomputedTable};
use palpate_tests::firmware_box_tables;

/// Tick `t` of the script: two probes of radius 2 mm come down on the top
/// face (z = 3 cm) 0.1 mm per tick, slide apart in x, the second turns into
/// a blade for ticks 30-34, a non-finite position at tick 40 (reset after
/// 41), then both lift.
fn tools_at(t: u32) -> [Tool; 2] {
    let t = t as f32;
    let down = t.min(25.0) * 1e-4;
    let slide = (t - 25.0).clamp(0.0, 15.0) * 2e-4;
    let lift = (t - 45.0).max(0.0) * 1e-3;
    let z = 0.0325 - down + lift;
    let mut tools = [
        Tool {
            position_m: [0.012 - slide, 0.013, z],
            action: ToolAction::Touch as u32,
            blade_m: [0.0; 3],
        },
        Tool {
            position_m: [0.018 + slide, 0.021, z],
            action: ToolAction::Touch as u32,
            blade_m: [0.0; 3],
        },
    ];
    if (30.0..35.0).contains(&t) {
        tools[1].action = ToolAction::Cut as u32;
        tools[1].blade_m = [0.0, 0.0, -0.01];
    }
    if t == 40.0 {
        tools[0].position_m[0] = f32::NAN;
    }
    tools
}

fn kernel_inputs(tools: &[Tool; 2]) -> [ToolInput<f32>; 2] {
    tools.map(|t| ToolInput {
        position_m: t.position_m.into(),
        action: if t.action == ToolAction::Cut as u32 {
            Action::Cut {
                blade_m: t.blade_m.into(),
            }
        } else {
            Action::Touch
        },
    })
}

fn bits(v: &[[f32; 3]]) -> Vec<u32> {
    v.iter().flatten().map(|x| x.to_bits()).collect()
}

#[test]
fn abi_loop_is_the_kernel_loop_with_two_points_parked() {
    let bytes = firmware_box_tables().precomputed.bytes();
    let table = super::table::precomputed();
    let config = LoopConfig {
        tool_points: 2,
        ..palpate_loop_config_default()
    };
    let mut abi = Box::<PrecomputedLoop>::default();
    // SAFETY: live handles; the table outlives the loop.
    let status = unsafe {
        palpate_precomputed_loop_create(&mut *abi, &*table, &config, core::ptr::null_mut())
    };
    assert_eq!(status, Status::Ok);

    let kernel_table = PrecomputedTable::<f32>::load(bytes).unwrap();
    let mut kernel = KernelLoop::<f32, 2, 2>::new(
        PrecomputedTissue::new(&kernel_table),
        KernelConfig {
            radius_m: 0.002,
            dt_s: 0.001,
            limits: SafetyLimits {
                max_force_n: 4.0,
                max_slew_n_per_s: 2000.0,
            },
        },
    )
    .unwrap();
    let model = PrecomputedModel::new(kernel_table);
    let (mut touching, mut cut_refused, mut faulted) = (0, 0, 0);
    for t in 0..60 {
        let tools = tools_at(t);
        let mut force = Force {
            force_n: [9.0; 3],
            status: OutputStatus::Clamped,
            contacts: 9,
            refused: 9,
            cut_refused: false,
        };
        // SAFETY: a live loop; 2 readable tools; a writable force.
        let status =
            unsafe { palpate_precomputed_loop_tick(&mut *abi, tools.as_ptr(), 2, &mut force) };
        assert_eq!(status, Status::Ok);
        let out = kernel.tick_tools(&kernel_inputs(&tools));
        assert_eq!(force, Force::from(&out), "tick {t}");
        assert_eq!(
            bits(&[force.force_n]),
            bits(&[out.force_n.into()]),
            "tick {t}"
        );
        touching += usize::from(force.contacts == 2);
        cut_refused += usize::from(force.cut_refused);
        faulted += usize::from(force.status == OutputStatus::FaultNonFiniteInput);
        if t % 10 == 5 {
            let mut ours = vec![[7.0f32; 3]; 64];
            // SAFETY: a live loop; 64 writable vertices.
            let status = unsafe {
                palpate_precomputed_loop_displacements(
                    &*abi,
                    ours.as_mut_ptr(),
                    64,
                    core::ptr::null_mut(),
                )
            };
            assert_eq!(status, Status::Ok);
            let mut theirs = vec![[0.0f32; 3]; 64];
            if let Some(solution) = kernel.solution() {
                model.displacements(solution, &mut theirs).unwrap();
            }
            assert_eq!(bits(&ours), bits(&theirs), "field at tick {t}");
        }
        if t == 41 {
            // SAFETY: a live loop.
            assert_eq!(
                unsafe { palpate_precomputed_loop_reset(&mut *abi) },
                Status::Ok
            );
            kernel.reset();
        }
    }
    // The script did what it says: both probes in contact most of the way,
    // the blade refused while it touched, the fault latched for two ticks.
    assert!(touching >= 30, "{touching} ticks with two contacts");
    assert_eq!((cut_refused, faulted), (5, 2));
}

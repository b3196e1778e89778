//! The hybrid haptic loop through the C ABI (`ffi/src/hybrid_loop.rs`): over
//! one memory block of `palpate_hybrid_memory_size` bytes it gives bit for
//! bit the kernel's own loop over heap buffers (RR-3510 §6.2), a probe
//! pressing the pre-computed region, then the tensor-mass corner, with a
//! physics update every tick; the whole mesh's displacement field too. The
//! three tables of another build are refused.

use palpate::hybrid::owned::OwnedHybridBuffers;
use palpate::tensor_mass::OwnedState;
use palpate_ffi::haptic::{Force, PhysicsReport, Tool, ToolAction, palpate_loop_config_default};
use palpate_ffi::hybrid_loop::{
    HybridLoop, palpate_hybrid_loop_create, palpate_hybrid_loop_displacements,
    palpate_hybrid_loop_physics_update, palpate_hybrid_loop_tick, palpate_hybrid_memory_size,
};
use palpate_ffi::status::Status;
use palpate_ffi::table::{
    Table, palpate_interface_table_load, palpate_precomputed_table_load,
    palpate_tensor_mass_table_load,
};
use palpate_kernel::PrecomputedTable;
use palpate_kernel::haptic::HybridLoop as KernelLoop;
use palpate_kernel::hybrid::HybridTissue;
use palpate_kernel::table::{InterfaceTable, TensorMassTable};
use palpate_kernel::tensor_mass::{
    DynamicParams, Integrator, PhysicsConfig as KernelPhysics, TensorMassModel,
};
use palpate_tests::firmware_box_tables;

use super::dynamic_loop::{Surface, block, box_physics, kernel_config, no_force};
use super::table::loaded;

fn bits(v: &[[f32; 3]]) -> Vec<u32> {
    v.iter().flatten().map(|x| x.to_bits()).collect()
}

/// Tick `t`: a probe 0.1 mm per tick into the top face above the
/// pre-computed region for 15 ticks, lifted, then into the tensor-mass
/// corner cell (x, y > 2 cm) for 15.
fn probe_at(t: u32) -> [Tool; 1] {
    let (x, y, k) = if t < 15 {
        (0.012, 0.013, t)
    } else if t < 20 {
        (0.012, 0.013, 0)
    } else {
        (0.025, 0.026, t - 20)
    };
    let lifted = (15..20).contains(&t);
    [Tool {
        position_m: [
            x,
            y,
            0.0325 - 1e-4 * k as f32 + if lifted { 0.01 } else { 0.0 },
        ],
        action: ToolAction::Touch as u32,
        blade_m: [0.0; 3],
    }]
}

#[test]
fn abi_hybrid_loop_is_the_kernels() {
    let tables = &firmware_box_tables().hybrid;
    let handles: [Box<Table>; 3] = [
        loaded(palpate_precomputed_table_load, tables.precomputed.bytes()),
        loaded(palpate_tensor_mass_table_load, tables.dynamic.bytes()),
        loaded(palpate_interface_table_load, tables.interface.bytes()),
    ];
    let [precomputed, dynamic, interface] = &handles;
    let physics = box_physics();
    let config = palpate_loop_config_default();
    let mut size = 0usize;
    // SAFETY: live handles; a writable size.
    let status = unsafe {
        palpate_hybrid_memory_size(
            &**precomputed,
            &**dynamic,
            &**interface,
            &physics,
            &mut size,
        )
    };
    assert_eq!(status, Status::Ok);
    let mut memory = block(size);
    let mut abi = Box::<HybridLoop>::default();
    let create = |abi: &mut HybridLoop, dynamic: &Table, memory: &mut [u64], bytes: usize| {
        // SAFETY: live handles; `memory` holds `bytes` writable bytes,
        // 8-byte aligned, and outlives the loop's use below.
        unsafe {
            palpate_hybrid_loop_create(
                abi,
                &**precomputed,
                dynamic,
                &**interface,
                &config,
                &physics,
                memory.as_mut_ptr().cast(),
                bytes,
                core::ptr::null_mut(),
            )
        }
    };
    // The whole box's tensor-mass table is not this hybrid's region.
    let other = loaded(
        palpate_tensor_mass_table_load,
        firmware_box_tables().tensor_mass.bytes(),
    );
    let mut other_size = 0usize;
    // SAFETY: as above.
    let status = unsafe {
        palpate_hybrid_memory_size(
            &**precomputed,
            &*other,
            &**interface,
            &physics,
            &mut other_size,
        )
    };
    assert_eq!(status, Status::Ok);
    let mut other_memory = block(other_size);
    assert_eq!(
        create(&mut abi, &other, &mut other_memory, other_size),
        Status::HybridMismatch
    );
    assert_eq!(create(&mut abi, dynamic, &mut memory, size), Status::Ok);

    let pre = PrecomputedTable::<f32>::load(tables.precomputed.bytes()).unwrap();
    let region = TensorMassTable::<f32>::load(tables.dynamic.bytes()).unwrap();
    let inter = InterfaceTable::<f32>::load(tables.interface.bytes()).unwrap();
    let mut state = OwnedState::for_table(&region).without_split_terms();
    let model =
        TensorMassModel::new(region, state.buffers(), DynamicParams::linear(20.0, 0.01)).unwrap();
    let mut surface = Surface::for_table(&region);
    let (surface_buffers, forces) = surface.buffers();
    let mut owned = OwnedHybridBuffers::for_tables(&pre, &region, &inter);
    let (coupling, hybrid_surface) = owned.buffers();
    let tissue = HybridTissue::<f32, 1, 1>::new(
        model,
        surface_buffers,
        forces,
        KernelPhysics::new(Integrator::SymplecticEuler, 0.0005, 2),
        pre,
        inter,
        coupling,
        hybrid_surface,
    )
    .unwrap();
    let mut kernel = KernelLoop::<f32, 1, 1>::new(tissue, kernel_config()).unwrap();

    let (mut on_precomputed, mut on_dynamic) = (0, 0);
    for t in 0..35 {
        let tools = probe_at(t);
        let mut force = no_force();
        // SAFETY: a live loop; one readable tool; a writable force.
        let status = unsafe { palpate_hybrid_loop_tick(&mut *abi, tools.as_ptr(), 1, &mut force) };
        assert_eq!(status, Status::Ok);
        let out = kernel.tick(&[tools[0].position_m.into()]);
        assert_eq!(force, Force::from(&out), "tick {t}");
        if force.contacts == 1 {
            if t < 15 {
                on_precomputed += 1;
            } else {
                on_dynamic += 1;
            }
        }
        let mut report = PhysicsReport {
            kinetic_energy_j: -1.0,
            force_evaluations: 0,
            removed_tets: 99,
        };
        // SAFETY: a live loop; a writable report.
        let status = unsafe {
            palpate_hybrid_loop_physics_update(&mut *abi, &mut report, core::ptr::null_mut())
        };
        assert_eq!(status, Status::Ok);
        let step = kernel.physics_update().unwrap();
        assert_eq!(
            report.kinetic_energy_j.to_bits(),
            step.kinetic_energy_j.to_bits(),
            "tick {t}"
        );
        if t == 12 || t == 34 {
            let mut ours = vec![[0.0f32; 3]; 64];
            // SAFETY: a live loop; 64 writable vertices.
            let status = unsafe {
                palpate_hybrid_loop_displacements(
                    &*abi,
                    ours.as_mut_ptr(),
                    64,
                    core::ptr::null_mut(),
                )
            };
            assert_eq!(status, Status::Ok);
            let mut theirs = vec![[0.0f32; 3]; 64];
            let tissue = kernel.tissue();
            tissue
                .region()
                .displacements(tissue.dynamic().model(), tissue.solution(), &mut theirs)
                .unwrap();
            assert_eq!(bits(&ours), bits(&theirs), "field at tick {t}");
            assert!(
                ours.iter().flatten().any(|&u| u < -1e-5),
                "pressed at tick {t}"
            );
        }
    }
    // The probe touches after 0.5 mm (5 ticks) of its 1.5 mm descents: up
    // to 10 ticks in contact on each region (the deforming surface is the
    // last update's, so one tick later there).
    assert!(
        (9..=10).contains(&on_precomputed) && (8..=10).contains(&on_dynamic),
        "{on_precomputed}, {on_dynamic}"
    );
}

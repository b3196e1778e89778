//! The dynamic haptic loop through the C ABI (`ffi/src/dynamic_loop.rs`):
//! over one memory block of exactly `palpate_dynamic_memory_size` bytes (one
//! byte less is refused) it gives bit for bit the kernel's own two-point
//! loop over heap buffers, tick and physics update after update: a probe
//! pressing, a blade cutting (the same tets removed), the displacement
//! field; then a divergence fault, refused until reset.

use palpate::tensor_mass::OwnedState;
use palpate_ffi::dynamic_loop::{
    DynamicLoop, palpate_dynamic_loop_create, palpate_dynamic_loop_displacements,
    palpate_dynamic_loop_physics_update, palpate_dynamic_loop_removed_tets,
    palpate_dynamic_loop_reset, palpate_dynamic_loop_tick, palpate_dynamic_memory_size,
};
use palpate_ffi::error::Error;
use palpate_ffi::haptic::{
    Extrapolation, Force, Integrator, Law, LoopConfig, OutputStatus, PhysicsConfig, PhysicsReport,
    Tool, ToolAction, palpate_loop_config_default,
};
use palpate_ffi::status::Status;
use palpate_kernel::haptic::{
    DynamicLoop as KernelLoop, LoopConfig as KernelConfig, SafetyLimits, ToolAction as Action,
    ToolInput,
};
use palpate_kernel::table::Plane;
use palpate_kernel::table::TensorMassTable;
use palpate_kernel::table::format::PLANE_LEN;
use palpate_kernel::tensor_mass::{
    DynamicParams, DynamicTissue, Integrator as KernelIntegrator, PhysicsConfig as KernelPhysics,
    SurfaceBuffers, TensorMassModel,
};
use palpate_tests::firmware_box_tables;

/// Linear, symplectic Euler, 2 steps of 0.5 ms per update (the box's
/// critical step is 1.47 ms), damping 20/s, bound 1 cm.
pub fn box_physics() -> PhysicsConfig {
    PhysicsConfig {
        law: Law::Linear as u32,
        incompressibility_n: 0.0,
        damping_per_s: 20.0,
        gravity_m_s2: [0.0; 3],
        max_displacement_m: 0.01,
        max_kinetic_energy_j: f32::INFINITY,
        integrator: Integrator::SymplecticEuler as u32,
        extrapolation: Extrapolation::Secant as u32,
        dt_s: 0.0005,
        substeps: 2,
        cut_capacity_tets: 8,
        cut_force_n: 0.2,
        tear_capacity_tets: 0,
        tear_volume_change: 0.0,
        tear_mean_elongation: 0.0,
        tear_max_elongation: 0.0,
    }
}

/// The kernel's loop configuration of the ABI's default.
pub fn kernel_config() -> KernelConfig<f32> {
    let c = palpate_loop_config_default();
    KernelConfig {
        radius_m: c.radius_m,
        dt_s: c.dt_s,
        limits: SafetyLimits {
            max_force_n: c.max_force_n,
            max_slew_n_per_s: c.max_slew_n_per_s,
        },
    }
}

/// Heap storage of a deforming surface with one grid cell per vertex (as
/// the ABI sizes it).
pub struct Surface {
    positions_m: Vec<[f32; 3]>,
    triangles: Vec<[u32; 3]>,
    face_slot: Vec<u32>,
    slot_tet: Vec<u32>,
    planes: Vec<Plane<f32>>,
    vertex_triangle_start: Vec<u32>,
    vertex_triangle: Vec<u32>,
    cell_start: Vec<u32>,
    grid_vertex: Vec<u32>,
    forces_n: Vec<[f32; 3]>,
}

impl Surface {
    pub fn for_table(table: &TensorMassTable<'_, f32>) -> Self {
        let l = SurfaceBuffers::<f32>::table_lengths(table, table.vertex_count());
        Self {
            positions_m: vec![[0.0; 3]; l.vertices],
            triangles: vec![[0; 3]; l.triangles],
            face_slot: vec![0; l.triangles],
            slot_tet: vec![0; l.triangles],
            planes: vec![[0.0; PLANE_LEN]; l.triangles],
            vertex_triangle_start: vec![0; l.vertex_triangle_start],
            vertex_triangle: vec![0; l.vertex_triangle],
            cell_start: vec![0; l.cell_start],
            grid_vertex: vec![0; l.vertices],
            forces_n: vec![[0.0; 3]; l.vertices],
        }
    }

    pub fn buffers(&mut self) -> (SurfaceBuffers<'_, f32>, &mut [[f32; 3]]) {
        (
            SurfaceBuffers {
                positions_m: &mut self.positions_m,
                triangles: &mut self.triangles,
                face_slot: &mut self.face_slot,
                slot_tet: &mut self.slot_tet,
                planes: &mut self.planes,
                vertex_triangle_start: &mut self.vertex_triangle_start,
                vertex_triangle: &mut self.vertex_triangle,
                cell_start: &mut self.cell_start,
                grid_vertex: &mut self.grid_vertex,
            },
            &mut self.forces_n,
        )
    }
}

/// Tick `t`: a probe comes down on the top face 0.1 mm per tick; from tick
/// 10 a blade 1 cm long stands in the far corner, cutting.
fn tools_at(t: u32) -> [Tool; 2] {
    let down = (t as f32).min(20.0) * 1e-4;
    let blade = t >= 10;
    [
        Tool {
            position_m: [0.012, 0.013, 0.0325 - down],
            action: ToolAction::Touch as u32,
            blade_m: [0.0; 3],
        },
        Tool {
            position_m: [0.025, 0.025, if blade { 0.0295 } else { 0.0325 }],
            action: if blade {
                ToolAction::Cut as u32
            } else {
                ToolAction::Touch as u32
            },
            blade_m: [0.0, 0.0, -0.01],
        },
    ]
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

/// A force output to be overwritten.
pub fn no_force() -> Force {
    Force {
        force_n: [f32::NAN; 3],
        status: OutputStatus::Clamped,
        contacts: 9,
        refused: 9,
        cut_refused: true,
    }
}

/// A memory block of `bytes` bytes, 8-byte aligned.
pub fn block(bytes: usize) -> Vec<u64> {
    vec![0u64; bytes.div_ceil(8)]
}

#[test]
fn abi_loop_is_the_kernel_loop_over_one_memory_block() {
    let bytes = firmware_box_tables().tensor_mass.bytes();
    let table = super::table::tensor_mass();
    let physics = box_physics();
    let config = LoopConfig {
        tool_points: 2,
        ..palpate_loop_config_default()
    };
    let mut size = 0usize;
    // SAFETY: live handles; a writable size.
    let status = unsafe { palpate_dynamic_memory_size(&*table, &physics, &mut size) };
    assert_eq!(status, Status::Ok);
    let mut memory = block(size);
    let mut abi = Box::<DynamicLoop>::default();
    let create =
        |abi: &mut DynamicLoop, memory: &mut [u64], bytes: usize, physics: &PhysicsConfig| {
            let mut error = Error::default();
            // SAFETY: live handles; `memory` holds at least `bytes` writable
            // bytes, 8-byte aligned, and outlives the loop's use below.
            unsafe {
                palpate_dynamic_loop_create(
                    abi,
                    &*table,
                    &config,
                    physics,
                    memory.as_mut_ptr().cast(),
                    bytes,
                    &mut error,
                )
            }
        };
    assert_eq!(
        create(&mut abi, &mut memory, size - 1, &physics),
        Status::MemoryTooSmall
    );
    assert_eq!(create(&mut abi, &mut memory, size, &physics), Status::Ok);

    let kernel_table = TensorMassTable::<f32>::load(bytes).unwrap();
    let mut state = OwnedState::for_table(&kernel_table).without_split_terms();
    let model = TensorMassModel::new(
        kernel_table,
        state.buffers(),
        DynamicParams::linear(20.0, 0.01),
    )
    .unwrap();
    let mut surface = Surface::for_table(&kernel_table);
    let (buffers, forces) = surface.buffers();
    let kernel_physics = KernelPhysics::new(KernelIntegrator::SymplecticEuler, 0.0005, 2);
    let tissue = DynamicTissue::<f32, 2>::new(model, buffers, forces, kernel_physics).unwrap();
    let mut kernel = KernelLoop::<f32, 2, 2>::new(tissue, kernel_config()).unwrap();

    let mut removed_total = 0;
    for t in 0..30 {
        let tools = tools_at(t);
        let mut force = no_force();
        // SAFETY: a live loop; 2 readable tools; a writable force.
        let status = unsafe { palpate_dynamic_loop_tick(&mut *abi, tools.as_ptr(), 2, &mut force) };
        assert_eq!(status, Status::Ok);
        let out = kernel.tick_tools(&kernel_inputs(&tools));
        assert_eq!(force, Force::from(&out), "tick {t}");
        let mut report = PhysicsReport {
            kinetic_energy_j: -1.0,
            force_evaluations: 0,
            removed_tets: 99,
        };
        // SAFETY: a live loop; a writable report.
        let status = unsafe {
            palpate_dynamic_loop_physics_update(&mut *abi, &mut report, core::ptr::null_mut())
        };
        assert_eq!(status, Status::Ok, "tick {t}");
        let step = kernel.physics_update().unwrap();
        assert_eq!(
            report.kinetic_energy_j.to_bits(),
            step.kinetic_energy_j.to_bits()
        );
        let removed = kernel.tissue().removed();
        assert_eq!(report.removed_tets as usize, removed.len());
        let mut ours = [0u32; 64];
        let mut count = 0usize;
        // SAFETY: a live loop; 64 writable entries; a writable count.
        let status =
            unsafe { palpate_dynamic_loop_removed_tets(&*abi, ours.as_mut_ptr(), 64, &mut count) };
        assert_eq!(status, Status::Ok);
        assert_eq!(&ours[..count], removed, "tick {t}");
        removed_total += count;
    }
    // The probe pressed and the blade cut.
    assert!(removed_total > 0);
    let mut ours = vec![[0.0f32; 3]; 64];
    // SAFETY: a live loop; 64 writable vertices.
    let status = unsafe {
        palpate_dynamic_loop_displacements(&*abi, ours.as_mut_ptr(), 64, core::ptr::null_mut())
    };
    assert_eq!(status, Status::Ok);
    let theirs = kernel.tissue().model().displacements_m().unwrap();
    assert_eq!(bits(&ours), bits(theirs));
    assert!(ours[53][2] < -1e-4, "pressed: {:?}", ours[53]);

    // A displacement bound of 0.1 µm under gravity: the first update
    // diverges, the next tick latches a model fault, the field is refused;
    // reset clears it.
    let fragile = PhysicsConfig {
        gravity_m_s2: [0.0, 0.0, -9.81],
        max_displacement_m: 1e-7,
        ..physics
    };
    assert_eq!(create(&mut abi, &mut memory, size, &fragile), Status::Ok);
    let tools = tools_at(0);
    let mut force = no_force();
    // SAFETY: as above.
    unsafe {
        assert_eq!(
            palpate_dynamic_loop_tick(&mut *abi, tools.as_ptr(), 2, &mut force),
            Status::Ok
        );
        assert_eq!(
            palpate_dynamic_loop_physics_update(
                &mut *abi,
                core::ptr::null_mut(),
                core::ptr::null_mut()
            ),
            Status::FaultDisplacementBound
        );
        assert_eq!(
            palpate_dynamic_loop_tick(&mut *abi, tools.as_ptr(), 2, &mut force),
            Status::Ok
        );
        assert_eq!(force.status, OutputStatus::FaultModel);
        assert_eq!(force.force_n, [0.0; 3]);
        assert_eq!(
            palpate_dynamic_loop_displacements(&*abi, ours.as_mut_ptr(), 64, core::ptr::null_mut()),
            Status::FaultDisplacementBound
        );
        assert_eq!(palpate_dynamic_loop_reset(&mut *abi), Status::Ok);
        assert_eq!(
            palpate_dynamic_loop_displacements(&*abi, ours.as_mut_ptr(), 64, core::ptr::null_mut()),
            Status::Ok
        );
    }
    assert!(ours.iter().flatten().all(|&u| u == 0.0));
}

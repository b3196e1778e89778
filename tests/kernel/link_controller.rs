//! The controller's side of the link (`palpate_kernel::link::Controller`)
//! on hand-made updates: the held contact's force against the local
//! contact model's formula worked by hand, a contact made since the update
//! on the extrapolated surface, and every link fault (late, lost,
//! corrupted, duplicated, reordered, future-stamped frames; a stalled
//! host and its return): the status at each stage, the counters, and the
//! force never stepping by more than the slew limit.

use nalgebra::Vector3;
use palpate_kernel::haptic::{OutputStatus, SafetyFault, SafetyLimits, ToolAction, ToolInput};
use palpate_kernel::link::frame::MAX_FRAME_BYTES;
use palpate_kernel::link::{
    Controller, ControllerConfig, LinkStatus, LocalContact, Region, RegionVertex, Update,
};

type Ctl = Controller<1, 6, 4, 10>;
type Up = Update<1, 6, 4>;

const DT_S: f32 = 1e-3;
const RADIUS_M: f32 = 0.002;
/// The surface's plane, m.
const TOP_M: f32 = 0.03;
const K_N_PER_M: f32 = 100.0;

fn config(max_slew_n_per_s: f32) -> ControllerConfig {
    ControllerConfig {
        radius_m: RADIUS_M,
        dt_s: DT_S,
        limits: SafetyLimits {
            max_force_n: 10.0,
            max_slew_n_per_s,
        },
        extrapolate_ticks: 30,
        // No fade: the supervisor's slew limit alone ramps.
        ramp_ticks: 1,
        update_every_ticks: 10,
    }
}

/// A 10 cm square of the plane `z = TOP_M` (two triangles, normal +z)
/// moving at `vz_m_s`, `K_c = K_N_PER_M · I`; held: the tool at `tip_z_m`
/// pushes the tissue with `push_n` (N, along −z), `α` 0.5, offset 0.02 N.
fn region(held: Option<(f32, f32)>, vz_m_s: f32) -> Region<6, 4> {
    let mut k = [0.0; 9];
    k[0] = K_N_PER_M;
    k[4] = K_N_PER_M;
    k[8] = K_N_PER_M;
    let (tip_z_m, push_n) = held.unwrap_or((0.0, 0.0));
    let mut r = Region {
        tool: 0,
        held: held.is_some(),
        grip: false,
        contact: LocalContact {
            stiffness_tensor_n_per_m: k,
            normal: [0.0, 0.0, 1.0],
            tip_m: [0.0, 0.0, tip_z_m],
            force_n: [0.0, 0.0, -push_n],
            scale: 0.5,
            offset_n: 0.02,
        },
        ..Region::default()
    };
    for (x, y) in [(-0.05, -0.05), (0.05, -0.05), (0.05, 0.05), (-0.05, 0.05)] {
        let v = RegionVertex {
            position_m: [x, y, TOP_M],
            velocity_m_s: [0.0, 0.0, vz_m_s],
        };
        r.vertices.push(v).expect("capacity");
    }
    r.triangles.push([0, 1, 2]).expect("capacity");
    r.triangles.push([0, 2, 3]).expect("capacity");
    r
}

fn update(tick: u32, region: Region<6, 4>) -> Up {
    let mut u = Up {
        tick,
        period_ticks: 10,
        ..Up::default()
    };
    u.regions.push(region).expect("capacity");
    u
}

fn send(c: &mut Ctl, u: &Up, sequence: u32) {
    let mut out = vec![0u8; MAX_FRAME_BYTES];
    let n = u.encode(sequence, &mut out).expect("encode");
    c.receive(&out[..n]);
}

fn probe(z_m: f32) -> [ToolInput<f32>; 1] {
    [ToolInput::touch(Vector3::new(0.001, 0.002, z_m))]
}

/// Ticks up to (not including) `tick` with the probe at `z_m`.
fn run_to(c: &mut Ctl, tick: u32, z_m: f32) {
    while c.next_tick() < tick {
        c.tick(&probe(z_m));
    }
}

#[test]
fn a_held_contact_feels_the_local_model_worked_by_hand() {
    let mut c = Ctl::new(config(1e6)).expect("config");
    let out = c.tick(&probe(0.031));
    assert_eq!(
        (out.link, out.force_n),
        (LinkStatus::Lost, Vector3::zeros())
    );
    run_to(&mut c, 10, 0.031);
    // Updated after tick 9 with the tool at 31 mm pushing 0.5 N.
    send(&mut c, &update(9, region(Some((0.031, 0.5)), 0.0)), 0);
    // Tick 12, 3 ticks after: the tool 1 mm deeper. By hand:
    // F = 0.5 + α k · 1 mm + (1 − 3/10) · 0.02 = 0.5 + 0.05 + 0.014.
    run_to(&mut c, 12, 0.031);
    let out = c.tick(&probe(0.030));
    assert_eq!(out.link, LinkStatus::Fresh);
    assert_eq!(out.contacts, 1);
    let expected = 0.5 + 0.5 * K_N_PER_M * 0.001 + 0.7 * 0.02;
    // f32 rounding of a handful of operations on values near 0.5 N.
    assert!((out.force_n.z - expected).abs() < 1e-6, "{}", out.force_n.z);
    assert_eq!((out.force_n.x, out.force_n.y), (0.0, 0.0));
    // Pulled 12 mm out: 0.5 − 0.5 k · 12 mm + 0.6 · 0.02 < 0 would pull,
    // the probe lets go.
    let out = c.tick(&probe(0.043));
    assert_eq!((out.contacts, out.force_n), (0, Vector3::zeros()));
}

#[test]
fn a_contact_made_since_the_update_presses_the_extrapolated_surface() {
    let mut c = Ctl::new(config(1e6)).expect("config");
    run_to(&mut c, 10, 0.04);
    // The surface sinks at 0.1 m/s from 30 mm at the update after tick 9.
    send(&mut c, &update(9, region(None, -0.1)), 0);
    // Tick 15: τ = 6 ms, the surface at 29.4 mm; the sphere's bottom at
    // 31.5 − 2 = 29.5 mm: not touching.
    run_to(&mut c, 15, 0.04);
    let out = c.tick(&probe(0.0315));
    assert_eq!((out.contacts, out.force_n), (0, Vector3::zeros()));
    // Tick 16: τ = 7 ms, surface at 29.3 mm, the sphere's bottom at 29.0 mm:
    // 0.3 mm deep, F = k · 0.3 mm along +z (entered from outside).
    let out = c.tick(&probe(0.031));
    assert_eq!(out.contacts, 1);
    assert!(
        (out.force_n.z - K_N_PER_M * 0.0003).abs() < 1e-5,
        "{}",
        out.force_n.z
    );
}

#[test]
fn a_contact_found_inside_starts_from_zero_force() {
    let mut c = Ctl::new(config(1e6)).expect("config");
    run_to(&mut c, 10, 0.031);
    send(&mut c, &update(9, region(None, 0.0)), 0);
    // The sphere was already 1 mm into the surface before the update came:
    // no push from a contact it never made.
    let out = c.tick(&probe(0.031));
    assert_eq!((out.contacts, out.force_n.z), (1, 0.0));
    // Then 0.5 mm deeper: F = k · 0.5 mm.
    let out = c.tick(&probe(0.0305));
    assert!(
        (out.force_n.z - K_N_PER_M * 0.0005).abs() < 1e-5,
        "{}",
        out.force_n.z
    );
}

/// Statuses and forces of ticks `from..to` with the probe pressing.
fn statuses(c: &mut Ctl, to: u32) -> Vec<(LinkStatus, f32)> {
    let mut seen = Vec::new();
    while c.next_tick() < to {
        let out = c.tick(&probe(0.031));
        seen.push((out.link, out.force_n.z));
    }
    seen
}

#[test]
fn a_stalled_host_ramps_to_zero_then_recovers_without_a_jump() {
    // 2 N/s: 2 mN per tick.
    let slew = 2.0;
    let mut c = Ctl::new(config(slew)).expect("config");
    run_to(&mut c, 10, 0.031);
    send(&mut c, &update(9, region(Some((0.031, 0.05)), 0.0)), 0);
    // Fresh to tick 19 (the period), extrapolating to tick 49 (30 more),
    // then the ramp down, then lost.
    let seen = statuses(&mut c, 120);
    let at = |t: u32| seen[(t - 10) as usize];
    assert_eq!(at(19).0, LinkStatus::Fresh);
    assert_eq!(at(20).0, LinkStatus::Extrapolating);
    assert_eq!(at(49).0, LinkStatus::Extrapolating);
    assert_eq!(at(50).0, LinkStatus::StaleRamping);
    assert!(at(49).1 > 0.049, "held until the timeout: {}", at(49).1);
    assert_eq!(at(119), (LinkStatus::Lost, 0.0));
    let ramp: Vec<_> = seen
        .iter()
        .filter(|s| s.0 == LinkStatus::StaleRamping)
        .collect();
    // From about 0.05 N at 2 mN per tick: 25 ticks of ramp.
    assert!((24..=26).contains(&ramp.len()), "{}", ramp.len());
    // The host returns: the force comes back through the slew limit.
    send(&mut c, &update(119, region(Some((0.031, 0.05)), 0.0)), 1);
    let back = statuses(&mut c, 160);
    assert_eq!(back[0].0, LinkStatus::Fresh);
    assert!(back[0].1 > 0.0 && back[0].1 <= slew * DT_S * 1.0001);
    assert!(back.last().expect("ticks").1 > 0.049);
    let all: Vec<f32> = seen.iter().chain(&back).map(|s| s.1).collect();
    for w in all.windows(2) {
        assert!((w[1] - w[0]).abs() <= slew * DT_S * 1.0001, "a jump: {w:?}");
    }
}

#[test]
fn duplicated_reordered_lost_corrupted_and_future_frames_are_counted() {
    let mut c = Ctl::new(config(1e6)).expect("config");
    run_to(&mut c, 40, 0.031);
    let held = |push| region(Some((0.031, push)), 0.0);
    send(&mut c, &update(9, held(0.1)), 0);
    send(&mut c, &update(29, held(0.3)), 2); // frame 1 lost
    send(&mut c, &update(19, held(0.2)), 1); // late: older than 29
    send(&mut c, &update(29, held(0.3)), 2); // duplicate
    send(&mut c, &update(40, held(0.4)), 3); // the tick 40 has not run
    let mut out = vec![0u8; MAX_FRAME_BYTES];
    let n = update(39, held(0.5)).encode(4, &mut out).expect("encode");
    out[n / 2] ^= 0x40; // corrupted on the line
    c.receive(&out[..n]);
    let k = c.counters();
    assert_eq!(k.accepted, 2);
    assert_eq!(k.gaps, 1);
    assert_eq!(k.out_of_order, 2);
    assert_eq!(k.rejected, 1);
    assert!(k.corrupt >= 1);
    assert_eq!(c.update().map(|u| u.tick), Some(29));
    // Tick 40, past the period of the update at tick 29 (to tick 39):
    // extrapolated from it.
    let o = c.tick(&probe(0.031));
    assert_eq!(o.link, LinkStatus::Extrapolating);
    assert!((o.force_n.z - 0.3).abs() < 1e-6, "{}", o.force_n.z);
    // Frames return: the next in order is taken.
    send(&mut c, &update(40, held(0.4)), 5);
    assert_eq!(c.counters().gaps, 3, "frames 3 and 4 never arrived whole");
    assert_eq!(c.update().map(|u| u.tick), Some(40));
}

#[test]
fn a_non_finite_tool_latches_a_fault_until_reset() {
    let mut c = Ctl::new(config(1e6)).expect("config");
    run_to(&mut c, 10, 0.031);
    send(&mut c, &update(9, region(Some((0.031, 0.5)), 0.0)), 0);
    let out = c.tick(&probe(f32::NAN));
    assert_eq!(
        out.status,
        OutputStatus::Faulted(SafetyFault::NonFiniteInput)
    );
    assert_eq!(c.tick(&probe(0.031)).force_n, Vector3::zeros());
    c.reset();
    assert_eq!(c.tick(&probe(0.031)).status, OutputStatus::Ok);
}

#[test]
fn command_batches_carry_every_tick_and_close_with_the_schedule() {
    let mut c = Ctl::new(config(1e6)).expect("config");
    let mut out = vec![0u8; MAX_FRAME_BYTES];
    let mut batches = Vec::new();
    for k in 0..25u32 {
        let mut t = probe(0.03 + k as f32 * 1e-5);
        if k == 24 {
            t[0].action = ToolAction::Grip;
        }
        c.tick(&t);
        let n = c.command_frame(&mut out).expect("encode");
        if n > 0 {
            let (frame, _) = palpate_kernel::link::FrameView::parse(&out[..n]).expect("frame");
            let cmd = palpate_kernel::link::Command::<1, 10>::decode(frame.payload).expect("cmd");
            batches.push((frame.sequence, cmd.first_tick, cmd.samples.len()));
        }
    }
    assert_eq!(batches, [(0, 0, 10), (1, 10, 10)]);
    assert_eq!(c.counters().unsent, 0);
}

//! The link's controller side (`palpate_kernel::link::Controller`): `new`,
//! `receive` on volatile bytes (any frame, valid or not), `tick` on volatile
//! tool points, `command_frame`, `reset`, `counters`.

use core::ptr::{addr_of, addr_of_mut, read_volatile, write_volatile};

use palpate_kernel::haptic::SafetyLimits;
use palpate_kernel::link::frame::MAX_FRAME_BYTES;
use palpate_kernel::link::{
    Controller, ControllerConfig, LINK_SAMPLES, LINK_TRIANGLES, LINK_VERTICES, LinkStatus,
};

use super::{TOOL_POINTS, TOOLS_AT_REST, ToolInputs};

/// Bytes received per tick, at most.
const RX: usize = 1024;

/// The controller's inputs, read with `read_volatile` only.
struct LinkInputs {
    /// Tool radius (m), tick (s), force clamp (N), slew (N/s).
    config: [f32; 4],
    /// Extrapolation timeout, fade and schedule, ticks.
    ticks_config: [u32; 3],
    /// Ticks per round.
    ticks: u32,
    /// Bytes received before each tick, and how many.
    rx: [u8; RX],
    rx_len: usize,
    /// The tool points each tick.
    tools: ToolInputs,
    /// Non-zero: `reset` before the tick.
    reset: u8,
}

static mut LINK_INPUTS: LinkInputs = LinkInputs {
    config: [0.002, 1e-3, 4.0, 2000.0],
    ticks_config: [30, 100, 10],
    ticks: 1,
    rx: [0; RX],
    rx_len: 0,
    tools: TOOLS_AT_REST,
    reset: 0,
};

/// What the controller produced, written with `write_volatile` only.
struct LinkOutputs {
    force_n: [f32; 3],
    link: u8,
    contacts: u8,
    counters: [u32; 6],
    frame_len: usize,
    frame: [u8; MAX_FRAME_BYTES],
}

static mut LINK_OUTPUTS: LinkOutputs = LinkOutputs {
    force_n: [0.0; 3],
    link: 0,
    contacts: 0,
    counters: [0; 6],
    frame_len: 0,
    frame: [0; MAX_FRAME_BYTES],
};

/// Builds a controller, then per tick takes volatile bytes and tool points
/// and publishes the force, the status, the counters and the command frame.
pub fn controller_step() {
    // SAFETY: single-threaded; plain-old-data static.
    let inputs = unsafe { read_volatile(addr_of!(LINK_INPUTS)) };
    let [radius_m, dt_s, max_force_n, max_slew_n_per_s] = inputs.config;
    let [extrapolate_ticks, ramp_ticks, update_every_ticks] = inputs.ticks_config;
    let config = ControllerConfig {
        radius_m,
        dt_s,
        limits: SafetyLimits {
            max_force_n,
            max_slew_n_per_s,
        },
        extrapolate_ticks,
        ramp_ticks,
        update_every_ticks,
    };
    let Ok(mut c) =
        Controller::<TOOL_POINTS, LINK_VERTICES, LINK_TRIANGLES, LINK_SAMPLES>::new(config)
    else {
        return;
    };
    let mut frame = [0u8; MAX_FRAME_BYTES];
    for _ in 0..inputs.ticks {
        // SAFETY: as above.
        let tick = unsafe { read_volatile(addr_of!(LINK_INPUTS)) };
        c.receive(tick.rx.get(..tick.rx_len).unwrap_or(&tick.rx));
        if tick.reset != 0 {
            c.reset();
        }
        let out = c.tick(&tick.tools.inputs());
        let n = c.command_frame(&mut frame).unwrap_or(0);
        let k = c.counters();
        let link = match out.link {
            LinkStatus::Fresh => 0,
            LinkStatus::Extrapolating => 1,
            LinkStatus::StaleRamping => 2,
            LinkStatus::Lost => 3,
        };
        let o = addr_of_mut!(LINK_OUTPUTS);
        // SAFETY: single-threaded; plain-old-data fields of a live static.
        unsafe {
            write_volatile(addr_of_mut!((*o).force_n), out.force_n.into());
            write_volatile(addr_of_mut!((*o).link), link);
            write_volatile(addr_of_mut!((*o).contacts), out.contacts);
            write_volatile(
                addr_of_mut!((*o).counters),
                [
                    k.accepted,
                    k.corrupt,
                    k.rejected,
                    k.out_of_order,
                    k.gaps,
                    k.unsent,
                ],
            );
            write_volatile(addr_of_mut!((*o).frame_len), n);
            write_volatile(addr_of_mut!((*o).frame), frame);
        }
    }
}

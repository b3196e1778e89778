//! `palpate session serve`: the scene's physics on the host for a haptic
//! controller across a link ([`palpate_kernel::link`]; Cotin 1999 §4: the
//! local contact model between physics updates).
//!
//! The host keeps a mirror of the controller's haptic loop: it ticks the
//! scene's dynamic loop with every tick's tool points the controller sends
//! ([`Command`] batches), and after every `every`-th tick, the in-process
//! schedule, runs the physics update and sends an [`Update`]: per tool
//! point, the surface triangles nearest it (positions and velocities) and
//! its local contact model (the held contact's [`HeldContact`] fields, or
//! the nearest triangle's `K_c` at its centroid). A controller fed these
//! with the same schedule sends the in-process loop's force, bit for bit,
//! while its contacts are held.
//!
//! Bounded: the receive buffer is [`RX_BYTES`]; a command's ticks that the
//! host already ran are skipped, ticks the controller skipped (a lost
//! command) are filled with its last tool points, at most
//! [`MAX_FILLED_TICKS`] at once (more is an error naming the peer).

use core::net::SocketAddr;
use std::io::{Read, Write};
use std::net::{TcpListener, TcpStream};

use anyhow::{Context, bail};

use crate::limits::{MAX_FILLED_TICKS, PEER_TIMEOUT};
use nalgebra::{Matrix3, Vector3};
use palpate_kernel::haptic::{DynamicLoop, ToolInput};
use palpate_kernel::link::controller::RX_BYTES;
use palpate_kernel::link::frame::MAX_FRAME_BYTES;
use palpate_kernel::link::{
    Command, FrameKind, FrameReader, LINK_SAMPLES, LINK_TRIANGLES, LINK_VERTICES, LocalContact,
    Region, RegionVertex, Update,
};
use palpate_kernel::math::Dispatch;
use palpate_kernel::table::TensorMassTable;
use palpate_kernel::table::{DEAD_TRIANGLE, VertexIndex};
use palpate_kernel::tensor_mass::{DynamicTissue, HeldContact};

use super::model::{SceneModel, SceneTables};
use super::setup::DynamicSetup;
use super::stability::check_stable_step;
use super::tool_points::{ForToolPoints, with_tool_points};
use crate::dispatch::HostDispatch;
use crate::scene::{ModelSpec, Scene};
use crate::threads::Threaded;

/// An update of `P` tool points at the link's default capacities.
pub type LinkUpdate<const P: usize> = Update<P, LINK_VERTICES, LINK_TRIANGLES>;

/// A command batch of `P` tool points at the link's default capacity.
pub type LinkCommand<const P: usize> = Command<P, LINK_SAMPLES>;

/// What a served session did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ServeCounters {
    /// Commands taken.
    pub commands: u32,
    /// Ticks run.
    pub ticks: u32,
    /// Ticks filled with the last tool points (the controller skipped them).
    pub filled: u32,
    /// Command samples skipped (ticks already run).
    pub repeated: u32,
    /// Updates sent.
    pub updates: u32,
    /// Frames dropped: corrupt (the reader) or not a valid command.
    pub dropped: u32,
}

/// The update after tick `stamp` of a physics period of `period_ticks`
/// ticks, the tool points at `tools` (m): one region per tool point.
pub fn link_update<const P: usize, D: Dispatch>(
    tissue: &DynamicTissue<'_, '_, f32, P, D>,
    tools: &[Vector3<f32>; P],
    stamp: u32,
    period_ticks: u16,
) -> LinkUpdate<P> {
    let mut update = LinkUpdate::<P> {
        tick: stamp,
        period_ticks: period_ticks.max(1),
        ..LinkUpdate::<P>::default()
    };
    for (p, (tool, held)) in tools.iter().zip(tissue.held()).enumerate() {
        if let Some(region) = region(tissue, p, tool, held.as_ref()) {
            // One region per tool point: at most P.
            let _ = update.regions.push(region);
        }
    }
    update
}

/// Tool point `p`'s region: its held triangle first, then the triangles
/// whose centroids are nearest `tool`, while the vertices fit.
fn region<const P: usize, D: Dispatch>(
    tissue: &DynamicTissue<'_, '_, f32, P, D>,
    p: usize,
    tool: &Vector3<f32>,
    held: Option<&HeldContact<f32>>,
) -> Option<Region<LINK_VERTICES, LINK_TRIANGLES>> {
    let surface = tissue.surface();
    let positions = surface.positions_m();
    let velocities = tissue.model().velocities_m_s().ok()?;
    let at = |v: u32| positions.get(v as usize).map(|&x| Vector3::from(x));
    let centroid =
        |t: &[u32; 3]| -> Option<Vector3<f32>> { Some((at(t[0])? + at(t[1])? + at(t[2])?) / 3.0) };
    let mut near: Vec<(f32, usize)> = surface
        .triangles()
        .iter()
        .enumerate()
        .filter(|(_, t)| **t != DEAD_TRIANGLE)
        .filter_map(|(i, t)| centroid(t).map(|c| ((c - tool).norm_squared(), i)))
        .collect();
    near.sort_by(|a, b| a.0.total_cmp(&b.0));
    let first = held.map(|h| h.contact.triangle.get());
    let order = first
        .into_iter()
        .chain(near.iter().map(|&(_, i)| i).filter(|i| Some(*i) != first));
    let mut r = Region::<LINK_VERTICES, LINK_TRIANGLES> {
        tool: u8::try_from(p).ok()?,
        held: held.is_some(),
        grip: held.is_some_and(|h| h.contact.grip_offset_m.is_some()),
        ..Region::default()
    };
    let mut ids: Vec<u32> = Vec::new();
    for i in order {
        let Some(t) = surface.triangles().get(i) else {
            continue;
        };
        let fresh = t.iter().filter(|v| !ids.contains(v)).count();
        if r.triangles.is_full() || ids.len() + fresh > LINK_VERTICES {
            break;
        }
        let mut local = [0u8; 3];
        for (l, v) in local.iter_mut().zip(t) {
            let k = ids.iter().position(|x| x == v).unwrap_or_else(|| {
                ids.push(*v);
                ids.len() - 1
            });
            *l = k as u8;
        }
        let _ = r.triangles.push(local);
    }
    for v in &ids {
        let vertex = RegionVertex {
            position_m: *positions.get(*v as usize)?,
            velocity_m_s: *velocities.get(*v as usize)?,
        };
        let _ = r.vertices.push(vertex);
    }
    r.contact = match held {
        Some(h) => {
            let m = h.local_model();
            LocalContact {
                stiffness_tensor_n_per_m: row_major(&m.stiffness_tensor_n_per_m),
                normal: m.normal.into(),
                tip_m: m.tip_m.into(),
                force_n: m.force_n.into(),
                scale: m.scale,
                offset_n: m.offset_n,
            }
        }
        None => {
            let (triangle, weights) = beneath(surface.triangles(), positions, &near, tool)?;
            LocalContact {
                stiffness_tensor_n_per_m: row_major(&stiffness_at(tissue, triangle, weights)?),
                scale: 1.0,
                ..LocalContact::default()
            }
        }
    };
    Some(r)
}

/// Of the triangles `near` (by centroid distance, nearest first), the
/// first whose plane has `tool`'s projection inside, else the nearest, and
/// the projection's barycentric weights (clamped to the triangle): where a
/// contact made before the next update most likely is.
fn beneath(
    triangles: &[[u32; 3]],
    positions: &[[f32; 3]],
    near: &[(f32, usize)],
    tool: &Vector3<f32>,
) -> Option<(usize, [f32; 3])> {
    let weights = |i: usize| -> Option<[f32; 3]> {
        let t = triangles.get(i)?;
        let p = |k: usize| -> Option<Vector3<f32>> {
            Some(Vector3::from(*positions.get(*t.get(k)? as usize)?))
        };
        let (a, b, c) = (p(0)?, p(1)?, p(2)?);
        let n = (b - a).cross(&(c - a));
        let area = n.norm_squared();
        if area <= 0.0 {
            return None;
        }
        let w = [
            (b - tool).cross(&(c - tool)).dot(&n) / area,
            (c - tool).cross(&(a - tool)).dot(&n) / area,
            (a - tool).cross(&(b - tool)).dot(&n) / area,
        ];
        Some(w)
    };
    let inside = near.iter().take(LINK_TRIANGLES).find_map(|&(_, i)| {
        weights(i)
            .filter(|w| w.iter().all(|x| *x >= 0.0))
            .map(|w| (i, w))
    });
    inside.or_else(|| {
        let &(_, i) = near.first()?;
        let w = weights(i)?.map(|x| x.max(0.0));
        let sum: f32 = w.iter().sum();
        (sum > 0.0).then(|| (i, w.map(|x| x / sum)))
    })
}

/// `K_c` of surface triangle `t` at barycentric `weights`, N/m.
fn stiffness_at<const P: usize, D: Dispatch>(
    tissue: &DynamicTissue<'_, '_, f32, P, D>,
    t: usize,
    weights: [f32; 3],
) -> Option<Matrix3<f32>> {
    let surface = tissue.surface();
    let tri = surface.triangles().get(t)?;
    let n = surface.positions_m().len();
    let v = |i: usize| VertexIndex::new(*tri.get(i)?, n);
    Some(tissue.local_stiffness(&[v(0)?, v(1)?, v(2)?], weights))
}

fn row_major(m: &Matrix3<f32>) -> [f32; 9] {
    core::array::from_fn(|i| m[(i / 3, i % 3)])
}

/// The host's side of the link over a dynamic loop: the mirror of the
/// controller's loop, an update every `every` ticks.
pub struct LinkHost<'h, 'a, 's, const P: usize, D: Dispatch> {
    haptic: &'h mut DynamicLoop<'a, 's, f32, P, P, D>,
    every: u32,
    next_tick: u32,
    sequence: u32,
    last: Option<[ToolInput<f32>; P]>,
    /// What it did.
    pub counters: ServeCounters,
    /// The first failed physics update (no update is sent after it: the
    /// controller ramps its force to zero).
    pub physics_error: Option<String>,
}

impl<'h, 'a, 's, const P: usize, D: Dispatch> LinkHost<'h, 'a, 's, P, D> {
    /// A host at tick 0 over `haptic`, an update every `every` ticks.
    pub fn new(haptic: &'h mut DynamicLoop<'a, 's, f32, P, P, D>, every: u32) -> Self {
        Self {
            haptic,
            every: every.max(1),
            next_tick: 0,
            sequence: 0,
            last: None,
            counters: ServeCounters::default(),
            physics_error: None,
        }
    }

    /// Runs the command's ticks (module docs: repeated ones skipped,
    /// skipped ones filled); `send` gets each update frame.
    pub fn command(
        &mut self,
        command: &LinkCommand<P>,
        send: &mut dyn FnMut(&[u8]) -> std::io::Result<()>,
    ) -> anyhow::Result<()> {
        self.counters.commands += 1;
        let ahead = command.first_tick.wrapping_sub(self.next_tick);
        if ahead > 0 && ahead < u32::MAX / 2 {
            if ahead > MAX_FILLED_TICKS {
                bail!(
                    "commands skip from tick {} to tick {}: above {MAX_FILLED_TICKS} ticks",
                    self.next_tick,
                    command.first_tick
                );
            }
            let Some(last) = self.last else {
                bail!(
                    "the first command starts at tick {}, not 0",
                    command.first_tick
                );
            };
            for _ in 0..ahead {
                self.counters.filled += 1;
                self.tick(&last, send)?;
            }
        }
        for (i, sample) in command.samples.iter().enumerate() {
            let tick = command.first_tick.wrapping_add(i as u32);
            if tick != self.next_tick {
                self.counters.repeated += 1;
                continue;
            }
            self.tick(sample, send)?;
        }
        Ok(())
    }

    fn tick(
        &mut self,
        tools: &[ToolInput<f32>; P],
        send: &mut dyn FnMut(&[u8]) -> std::io::Result<()>,
    ) -> anyhow::Result<()> {
        self.haptic.tick_tools(tools);
        self.last = Some(*tools);
        let stamp = self.next_tick;
        self.next_tick = stamp.wrapping_add(1);
        self.counters.ticks += 1;
        if !self.next_tick.is_multiple_of(self.every) || self.physics_error.is_some() {
            return Ok(());
        }
        if let Err(e) = self.haptic.physics_update() {
            self.physics_error = Some(format!("tick {stamp}: {e}"));
            return Ok(());
        }
        let positions = tools.map(|t| t.position_m);
        let period = u16::try_from(self.every).unwrap_or(u16::MAX);
        let update = link_update(self.haptic.tissue(), &positions, stamp, period);
        let mut frame = [0u8; MAX_FRAME_BYTES];
        let n = update
            .encode(self.sequence, &mut frame)
            .map_err(|e| anyhow::anyhow!("update after tick {stamp}: {e}"))?;
        self.sequence = self.sequence.wrapping_add(1);
        self.counters.updates += 1;
        send(frame.get(..n).unwrap_or(&[])).context("sending an update")
    }

    /// Serves one controller on `stream` until it closes the connection
    /// (a clean end) or is silent for [`PEER_TIMEOUT`]; errors name `peer`.
    pub fn serve(&mut self, stream: &mut TcpStream, peer: &SocketAddr) -> anyhow::Result<()> {
        stream.set_read_timeout(Some(PEER_TIMEOUT))?;
        stream.set_nodelay(true)?;
        let mut reader = Box::new(FrameReader::<RX_BYTES>::new());
        let mut buf = [0u8; 4096];
        let mut out = stream.try_clone()?;
        let mut send = |b: &[u8]| out.write_all(b);
        loop {
            let n = match stream.read(&mut buf) {
                Ok(0) => break,
                Ok(n) => n,
                Err(e) => return Err(e).with_context(|| format!("controller {peer}")),
            };
            let mut rest = buf.get(..n).unwrap_or(&[]);
            while !rest.is_empty() {
                let taken = reader.push(rest);
                rest = rest.get(taken..).unwrap_or(&[]);
                while let Some(frame) = reader.next_frame() {
                    let command = match frame.kind {
                        FrameKind::Command => LinkCommand::<P>::decode(frame.payload).ok(),
                        FrameKind::Update => None,
                    };
                    let Some(command) = command else {
                        self.counters.dropped += 1;
                        continue;
                    };
                    self.command(&command, &mut send)
                        .with_context(|| format!("controller {peer}"))?;
                }
            }
        }
        self.counters.dropped += reader.corrupt();
        Ok(())
    }
}

/// Binds `addr`, a loopback address only (the link carries no
/// authentication), and returns the listener.
pub fn listen(addr: &SocketAddr) -> anyhow::Result<TcpListener> {
    if !addr.ip().is_loopback() {
        bail!(
            "--listen {addr}: only a loopback address (127.0.0.1, ::1) is served; the link has \
             no authentication"
        );
    }
    TcpListener::bind(addr).with_context(|| format!("--listen {addr}"))
}

/// The ticks between physics updates for `update_hz` at the scene's haptic
/// rate: the nearest whole number, at least 1 (30 Hz at 1 kHz: every 33
/// ticks, 30.3 Hz).
pub fn update_every(scene: &Scene, update_hz: f64) -> anyhow::Result<u32> {
    let haptic_hz = scene.rates.haptic_hz;
    if !(update_hz.is_finite() && update_hz > 0.0 && update_hz <= haptic_hz) {
        bail!(
            "--update-hz {update_hz}: must be finite, > 0 and at most the haptic rate {haptic_hz} Hz"
        );
    }
    Ok((haptic_hz / update_hz).round().max(1.0) as u32)
}

/// `palpate session serve`: builds the dynamic `scene`'s table with a
/// physics update every `every` ticks, then serves the first controller
/// that connects to `listener` until it disconnects. Refuses a scene that
/// is not on the dynamic model (the pre-computed model runs whole on the
/// controller).
pub fn serve_scene(
    scene: &Scene,
    listener: &TcpListener,
    every: u32,
    threads: usize,
) -> anyhow::Result<(ServeCounters, Option<String>)> {
    check_servable(scene)?;
    with_dynamic_setup(scene, every, |setup| {
        with_tool_points(
            scene.tool.kernel_points(),
            Serve {
                setup,
                listener,
                every,
                threads,
            },
        )
    })
}

/// Refuses a scene that is not on the dynamic model (the pre-computed
/// model runs whole on the controller; the hybrid is not served yet).
pub fn check_servable(scene: &Scene) -> anyhow::Result<()> {
    if !matches!(scene.model, ModelSpec::Dynamic(_)) || !scene.zones.is_empty() {
        bail!(
            "{}: session serve runs the dynamic model only (the pre-computed model runs whole on \
             the controller)",
            scene.source
        );
    }
    Ok(())
}

/// Runs `body` on dynamic `scene`'s setup with a physics update every
/// `every` ticks: the mesh loaded, the stable step checked, the table built
/// in memory (f32).
pub fn with_dynamic_setup<R>(
    scene: &Scene,
    every: u32,
    body: impl FnOnce(&DynamicSetup<'_>) -> anyhow::Result<R>,
) -> anyhow::Result<R> {
    let mut scene = scene.clone();
    scene.rates.physics_every = every;
    let (mesh, report) = scene.load_mesh()?;
    check_stable_step(&scene, &mesh, &report)?;
    let tables = SceneModel::of(&scene, &mesh, &report)?.tables(&scene, &mesh, &report, None)?;
    let SceneTables::Dynamic(file, spec) = &tables else {
        bail!("{}: not a dynamic scene", scene.source);
    };
    let table = TensorMassTable::<f32>::load(file.bytes())
        .map_err(|e| anyhow::anyhow!("session table: {e}"))?;
    body(&DynamicSetup::of(&scene, spec, table)?)
}

struct Serve<'a, 't> {
    setup: &'a DynamicSetup<'t>,
    listener: &'a TcpListener,
    every: u32,
    threads: usize,
}

impl ForToolPoints for Serve<'_, '_> {
    type Output = anyhow::Result<(ServeCounters, Option<String>)>;

    fn call<const P: usize>(self) -> Self::Output {
        let dispatch = Threaded::new(HostDispatch::detect(), self.threads);
        self.setup.with_loop::<P, _, _>(dispatch, |haptic| {
            let (mut stream, peer) = self.listener.accept().context("accepting a controller")?;
            let mut host = LinkHost::new(haptic, self.every);
            host.serve(&mut stream, &peer)?;
            Ok((host.counters, host.physics_error))
        })
    }
}

//! The pre-computed model (RR-3510 §4, MODELS.md §2) timed on a mesh: the
//! contact solve (the force path) for m = 1..=4 vertex contacts, the
//! displacement update of every free vertex, and the haptic tick
//! (detection and tracking in the collision grid, the solve, the
//! supervisor; MODELS.md §6) with m tool points pressing.
//!
//! The contacts: up to [`MAX_CONTACTS`] touchable vertices spread over the
//! surface (the highest first, then each the farthest from those already
//! chosen), among those whose surface triangles all face within 25° of the
//! vertex's normal (the area-weighted normal of its triangles: not on an
//! edge or a corner of the surface). The solve presses each vertex along
//! its inward normal by [`PRESS_OF_RADIUS`] tool radii; the tick's tool
//! points press as deep at the centroid of one of the vertex's triangles.
//! The tool radius is a quarter of the mean edge of those triangles.

use core::hint::black_box;

use anyhow::{Context, bail};
use nalgebra::Vector3;
use palpate_kernel::haptic::{LoopConfig, PrecomputedLoop, SafetyLimits};
use palpate_kernel::math::Dispatch;
use palpate_kernel::precomputed::PrecomputedTissue;
use palpate_kernel::{Constraint, MAX_CONTACTS, PrecomputedModel, PrecomputedTable, Real};

use super::measure::{Sampling, Timing, time};
use crate::mesh::{MeshReport, TetMesh};
use crate::table::build::{BuildOptions, build_with_limits};
use crate::table::estimate::SizeLimits;
use crate::table::file::Precision;
use crate::table::load::TableFile;

/// Depth of a pressed contact, in tool radii.
pub const PRESS_OF_RADIUS: f64 = 0.3;

/// A contact vertex: its index, rest position (m) and unit outward normal;
/// where the haptic tick's tool presses near it (the centroid of one of its
/// surface triangles, m, and that triangle's unit outward normal); the
/// mean edge length of that triangle (m).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Pick {
    vertex: u32,
    position_m: [f64; 3],
    normal: [f64; 3],
    touch_m: [f64; 3],
    touch_normal: [f64; 3],
    edge_m: f64,
}

/// The pre-computed tables of one mesh and the contacts they are timed
/// with.
pub struct PrecomputedBench {
    f32: Option<TableFile>,
    f64: Option<TableFile>,
    picks: Vec<Pick>,
    radius_m: f64,
    /// Free vertices `F`.
    free: usize,
}

/// A timed displacement update: its timing and the bytes it reads and
/// writes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UpdateTiming {
    /// Time per update.
    pub timing: Timing,
    /// `m` compliance columns of `F` 3×3 blocks and the `F` outputs
    /// (`benches/benches/precomputed_contact.rs`'s count).
    pub bytes: u64,
}

impl PrecomputedBench {
    /// Builds the pre-computed tables of `mesh` that `options` describe (a
    /// pre-computed kind) in each of `precisions`, each checked against
    /// `limits` before it is built, and picks the contacts.
    pub fn new(
        mesh: &TetMesh,
        report: &MeshReport,
        options: &BuildOptions,
        precisions: &[Precision],
        limits: &SizeLimits,
    ) -> anyhow::Result<Self> {
        let table = |precision: Precision| -> anyhow::Result<Option<TableFile>> {
            if !precisions.contains(&precision) {
                return Ok(None);
            }
            let options = BuildOptions {
                precision,
                progress: false,
                ..options.clone()
            };
            let built = build_with_limits(mesh, report, &options, limits)?;
            Ok(Some(TableFile::from_bytes(&built.bytes)))
        };
        let (f32, f64) = (table(Precision::F32)?, table(Precision::F64)?);
        let Some(any) = f64.as_ref().or(f32.as_ref()) else {
            bail!("no precision to build the pre-computed table in");
        };
        // Contact picks from the f64 rest positions when built (else f32's).
        let (picks, radius_m, free) = match (&f64, any) {
            (Some(file), _) => picks_of(&PrecomputedTable::<f64>::load(file.bytes())?),
            (None, file) => picks_of(&PrecomputedTable::<f32>::load(file.bytes())?),
        };
        if picks.is_empty() {
            bail!("the mesh has no touchable vertex (every surface vertex is fixed)");
        }
        Ok(Self {
            f32,
            f64,
            picks,
            radius_m,
            free,
        })
    }

    /// How many contacts can be timed: up to [`MAX_CONTACTS`], fewer on a
    /// mesh with fewer touchable vertices.
    pub fn max_contacts(&self) -> usize {
        self.picks.len()
    }

    fn file(&self, precision: Precision) -> anyhow::Result<&TableFile> {
        match precision {
            Precision::F32 => self.f32.as_ref(),
            Precision::F64 => self.f64.as_ref(),
        }
        .with_context(|| format!("no {precision:?} pre-computed table was built for this bench"))
    }

    /// The `m` contacts, each pressed by [`PRESS_OF_RADIUS`] radii.
    fn constraints<T: Real>(&self, m: usize) -> Vec<Constraint<T>> {
        let press = PRESS_OF_RADIUS * self.radius_m;
        self.picks
            .iter()
            .take(m)
            .map(|p| Constraint::at_vertex(p.vertex, vector(p.normal.map(|x| -x * press))))
            .collect()
    }

    /// Times the contact solve `contact_forces::<4>` of `m` vertex contacts.
    pub fn time_force_path(
        &self,
        m: usize,
        precision: Precision,
        sampling: &Sampling,
    ) -> anyhow::Result<Timing> {
        let file = self.file(precision)?;
        match precision {
            Precision::F32 => self.force_path_in::<f32>(file, m, sampling),
            Precision::F64 => self.force_path_in::<f64>(file, m, sampling),
        }
    }

    fn force_path_in<T: Real>(
        &self,
        file: &TableFile,
        m: usize,
        sampling: &Sampling,
    ) -> anyhow::Result<Timing> {
        let model = PrecomputedModel::new(PrecomputedTable::<T>::load(file.bytes())?);
        let set = self.constraints::<T>(m);
        model.contact_forces::<MAX_CONTACTS>(&set)?;
        Ok(time(sampling, || {
            let _ = black_box(model.contact_forces::<MAX_CONTACTS>(black_box(&set)));
        }))
    }

    /// Times `free_displacements_with` (every free vertex, free-index
    /// order) for the solved set of `m` vertex contacts, through
    /// `dispatch`.
    pub fn time_update(
        &self,
        m: usize,
        precision: Precision,
        dispatch: impl Dispatch,
        sampling: &Sampling,
    ) -> anyhow::Result<UpdateTiming> {
        let file = self.file(precision)?;
        let (timing, scalar) = match precision {
            Precision::F32 => (self.update_in::<f32>(file, m, dispatch, sampling)?, 4),
            Precision::F64 => (self.update_in::<f64>(file, m, dispatch, sampling)?, 8),
        };
        let (m, free) = (m.min(self.picks.len()) as u64, self.free as u64);
        Ok(UpdateTiming {
            timing,
            bytes: m * 9 * scalar * free + 3 * scalar * free,
        })
    }

    fn update_in<T: Real>(
        &self,
        file: &TableFile,
        m: usize,
        dispatch: impl Dispatch,
        sampling: &Sampling,
    ) -> anyhow::Result<Timing> {
        let model = PrecomputedModel::new(PrecomputedTable::<T>::load(file.bytes())?);
        let solution = model.contact_forces::<MAX_CONTACTS>(&self.constraints::<T>(m))?;
        let mut out = vec![[T::zero(); 3]; model.table().free_count()];
        Ok(time(sampling, || {
            let _ = model.free_displacements_with(dispatch, black_box(&solution), &mut out);
            black_box(&mut out);
        }))
    }

    /// Times one haptic tick with `m` tool points pressing (1 kHz, limits
    /// that never clamp), alternating between two depths so that the solve
    /// has work to do. An error if the points are not all in contact.
    pub fn time_tick(
        &self,
        m: usize,
        precision: Precision,
        sampling: &Sampling,
    ) -> anyhow::Result<Timing> {
        let file = self.file(precision)?;
        match (precision, m) {
            (Precision::F32, 1) => self.tick_in::<f32, 1>(file, sampling),
            (Precision::F32, 2) => self.tick_in::<f32, 2>(file, sampling),
            (Precision::F32, 3) => self.tick_in::<f32, 3>(file, sampling),
            (Precision::F32, 4) => self.tick_in::<f32, 4>(file, sampling),
            (Precision::F64, 1) => self.tick_in::<f64, 1>(file, sampling),
            (Precision::F64, 2) => self.tick_in::<f64, 2>(file, sampling),
            (Precision::F64, 3) => self.tick_in::<f64, 3>(file, sampling),
            (Precision::F64, 4) => self.tick_in::<f64, 4>(file, sampling),
            _ => bail!("the haptic tick is timed with 1 to {MAX_CONTACTS} tool points, not {m}"),
        }
    }

    fn tick_in<T: Real, const P: usize>(
        &self,
        file: &TableFile,
        sampling: &Sampling,
    ) -> anyhow::Result<Timing> {
        if P > self.picks.len() {
            bail!(
                "{P} tool points: the mesh has {} touchable vertices",
                self.picks.len()
            );
        }
        let table = PrecomputedTable::<T>::load(file.bytes())?;
        let config = LoopConfig {
            radius_m: T::of_f64(self.radius_m),
            dt_s: T::of_f64(1e-3),
            limits: SafetyLimits {
                max_force_n: T::of_f64(1e6),
                max_slew_n_per_s: T::of_f64(1e12),
            },
        };
        let mut haptic = PrecomputedLoop::<T, P, P>::new(PrecomputedTissue::new(&table), config)
            .map_err(|e| anyhow::anyhow!("haptic loop: {e}"))?;
        let r = self.radius_m;
        // The tool centre at `depth` (m) below first touch of pick `p`.
        let tool = |p: usize, depth: f64| -> Vector3<T> {
            let pick = &self.picks[p];
            vector(core::array::from_fn(|i| {
                pick.touch_m[i] + pick.touch_normal[i] * (r - depth)
            }))
        };
        // Approach from a radius above, then press in 10 ticks.
        haptic.tick(&core::array::from_fn(|p| tool(p, -r)));
        for k in 0..=10 {
            let depth = PRESS_OF_RADIUS * r * k as f64 / 10.0;
            haptic.tick(&core::array::from_fn(|p| tool(p, depth)));
        }
        let touching = haptic.contacts().iter().flatten().count();
        if touching != P {
            bail!("{touching} of the {P} tool points found the surface; the tick is not timed");
        }
        let depths = [PRESS_OF_RADIUS * r, 1.1 * PRESS_OF_RADIUS * r];
        let positions = depths.map(|d| core::array::from_fn::<_, P, _>(|p| tool(p, d)));
        let mut k = 0usize;
        let timing = time(sampling, || {
            k = k.wrapping_add(1);
            black_box(haptic.tick(black_box(&positions[k % 2])));
        });
        if haptic.contacts().iter().flatten().count() != P {
            bail!("the tool points lost the surface while the tick was timed");
        }
        Ok(timing)
    }
}

/// An f64 triple in `T`.
fn vector<T: Real>(v: [f64; 3]) -> Vector3<T> {
    Vector3::from(v.map(T::of_f64))
}

/// The contacts of `table` (module doc), the tool radius (m) and the free
/// vertex count.
fn picks_of<T: Real>(table: &PrecomputedTable<'_, T>) -> (Vec<Pick>, f64, usize) {
    let position = |v: u32| -> [f64; 3] {
        table
            .rest_positions()
            .get(v as usize)
            .map_or([0.0; 3], |p| p.map(T::as_f64))
    };
    let n = table.vertex_count();
    let touchable = &table.free_vertices()[..table.touchable_count()];
    let mut is_touchable = vec![false; n];
    for &v in touchable {
        is_touchable[v as usize] = true;
    }
    // Per vertex: its area-weighted normal and its surface triangles.
    let mut normal = vec![[0.0f64; 3]; n];
    let mut triangles_of: Vec<Vec<usize>> = vec![Vec::new(); n];
    let mut unit_normal = Vec::with_capacity(table.surface_triangles().len());
    for (t, &[a, b, c]) in table.surface_triangles().iter().enumerate() {
        let [pa, pb, pc] = [a, b, c].map(position);
        let (u, w) = (sub(pb, pa), sub(pc, pa));
        // (b − a) × (c − a): outward, twice the area.
        let cross = [
            u[1] * w[2] - u[2] * w[1],
            u[2] * w[0] - u[0] * w[2],
            u[0] * w[1] - u[1] * w[0],
        ];
        unit_normal.push(unit(cross));
        for v in [a, b, c] {
            let v = v as usize;
            for i in 0..3 {
                normal[v][i] += cross[i];
            }
            triangles_of[v].push(t);
        }
    }
    // A candidate: a touchable vertex whose triangles all face within 25°
    // of its normal (not an edge or a corner of the surface), with a
    // triangle of touchable vertices to press the tool on.
    let candidates: Vec<Pick> = touchable
        .iter()
        .filter_map(|&v| {
            let n_v = unit(normal[v as usize]);
            let tris = &triangles_of[v as usize];
            let flat = tris.iter().all(|&t| dot(unit_normal[t], n_v) > 0.9);
            let (&t, _) = tris
                .iter()
                .map(|t| (t, table.surface_triangles()[*t]))
                .find(|(_, tri)| tri.iter().all(|&x| is_touchable[x as usize]))?;
            let tri = table.surface_triangles()[t];
            let corners = tri.map(position);
            let centroid =
                core::array::from_fn(|i| corners.iter().map(|p| p[i]).sum::<f64>() / 3.0);
            let edge = (norm(sub(corners[1], corners[0]))
                + norm(sub(corners[2], corners[1]))
                + norm(sub(corners[0], corners[2])))
                / 3.0;
            flat.then_some(Pick {
                vertex: v,
                position_m: position(v),
                normal: n_v,
                touch_m: centroid,
                touch_normal: unit_normal[t],
                edge_m: edge,
            })
        })
        .collect();
    let mut picks: Vec<Pick> = Vec::with_capacity(MAX_CONTACTS);
    // The highest candidate first, then each the farthest from the picks.
    let mut next = candidates
        .iter()
        .max_by(|a, b| a.position_m[2].total_cmp(&b.position_m[2]));
    while let Some(&pick) = next {
        picks.push(pick);
        if picks.len() == MAX_CONTACTS {
            break;
        }
        let gap = |c: &Pick| {
            picks
                .iter()
                .map(|p| norm(sub(c.position_m, p.position_m)))
                .fold(f64::INFINITY, f64::min)
        };
        next = candidates
            .iter()
            .filter(|c| gap(c) > 0.0)
            .max_by(|a, b| gap(a).total_cmp(&gap(b)));
    }
    let mean_edge = picks.iter().map(|p| p.edge_m).sum::<f64>() / picks.len().max(1) as f64;
    (picks, 0.25 * mean_edge, table.free_count())
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn unit(a: [f64; 3]) -> [f64; 3] {
    let length = norm(a);
    a.map(|x| if length > 0.0 { x / length } else { 0.0 })
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn norm(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

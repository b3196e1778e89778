//! Local removal of tetrahedra (RR-3510 §5; Picinbono 2001 §3.1, MODELS.md
//! §1 and §3): a removed tet's 4 vertex blocks, 6 edge blocks and 4 mass
//! shares, and its St Venant-Kirchhoff split terms when the state keeps
//! them (about 250 values), are subtracted from the current state,
//! recomputed from the rest shape the table keeps for it, so the stored
//! terms equal those built from the mesh without the tet, to rounding.

use core::fmt;

use nalgebra::Vector3;

use super::edges::subtract_block as subtract_edge_block;
use super::model::TensorMassModel;
use super::stvk_terms::{TetPlace, tet_terms};
use crate::Real;
use crate::math::element::stiffness_block;
use crate::table::format::{TET_EDGE_PAIRS, tet_face_vertices};
use crate::table::{EdgeIndex, TetIndex, VertexIndex};

/// Why a tet was not removed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RemoveError {
    /// No such tet.
    TetOutOfRange {
        /// The tet index given.
        tet: u32,
    },
    /// The tet was removed before.
    AlreadyRemoved {
        /// The tet index given.
        tet: u32,
    },
}

impl fmt::Display for RemoveError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::TetOutOfRange { tet } => write!(f, "tet {tet} does not exist"),
            Self::AlreadyRemoved { tet } => write!(f, "tet {tet} is already removed"),
        }
    }
}

impl core::error::Error for RemoveError {}

impl<T: Real> TensorMassModel<'_, '_, T> {
    /// Removes `tet`, then every face neighbour it leaves with no live face
    /// neighbour (held to the rest by an edge or a vertex only), so the mesh
    /// stays conformal. Returns how many tets were removed (1 to 5).
    ///
    /// Bounded: a hanging tet has no live face neighbour, so removing it
    /// cannot leave another tet hanging; at most 4 follow the first.
    pub fn remove_tet(&mut self, tet: u32) -> Result<u32, RemoveError> {
        let t = self
            .table
            .tet(tet)
            .ok_or(RemoveError::TetOutOfRange { tet })?;
        self.remove(t, &mut |_| {})
    }

    /// [`Self::remove_tet`] of a checked tet, telling `removed` each tet it
    /// removes (`t` first).
    pub(super) fn remove(
        &mut self,
        t: TetIndex,
        removed: &mut dyn FnMut(TetIndex),
    ) -> Result<u32, RemoveError> {
        let tet = t.as_u32();
        match self.state.tet_alive.get(t.get()) {
            None => return Err(RemoveError::TetOutOfRange { tet }),
            Some(false) => return Err(RemoveError::AlreadyRemoved { tet }),
            Some(true) => {}
        }
        self.subtract(t);
        removed(t);
        let mut count = 1;
        for other in self.table.neighbours_of(t).into_iter().flatten() {
            if self.is_alive(other) && self.live_face_neighbours(other) == 0 {
                self.subtract(other);
                removed(other);
                count += 1;
            }
        }
        Ok(count)
    }

    /// `true` while `tet` has not been removed.
    pub(super) fn is_alive(&self, tet: TetIndex) -> bool {
        self.state.tet_alive.get(tet.get()) == Some(&true)
    }

    fn live_face_neighbours(&self, tet: TetIndex) -> usize {
        let neighbours = self.table.neighbours_of(tet).into_iter().flatten();
        neighbours.filter(|&o| self.is_alive(o)).count()
    }

    /// The current boundary surface: every face of a live tet whose
    /// neighbour across it is absent or removed, outward right-hand normal.
    /// Bounded by `4 × tet_count`.
    pub fn surface_triangles(&self) -> impl Iterator<Item = [u32; 3]> + '_ {
        let live = self.table.tet_indices().filter(move |&t| self.is_alive(t));
        live.flat_map(move |t| {
            let faces = self
                .table
                .tets()
                .get(t.get())
                .map(|&tet| tet_face_vertices(tet));
            faces
                .into_iter()
                .flatten()
                .zip(self.table.neighbours_of(t))
                .filter(move |(_, other)| !other.is_some_and(|o| self.is_alive(o)))
                .map(|(face, _)| face)
        })
    }

    /// Subtracts tet `t`'s blocks and St Venant-Kirchhoff terms (with its own
    /// Lamé coefficients) and mass shares and marks it removed. A vertex left
    /// without live tets is detached: mass, vertex tensor and velocity set to
    /// exactly zero (it keeps still).
    fn subtract(&mut self, t: TetIndex) {
        let (Some(tet), Some(edges), Some((a, volume)), Some((lambda, mu))) = (
            self.table.tet_vertices(t),
            self.table.tet_edge_indices(t),
            self.table.tet_shape(t.get()),
            self.table.tet_lame(t),
        ) else {
            return;
        };
        let share = T::of_f64(self.table.density_kg_m3()) * volume / T::of_f64(4.0);
        let s = &mut self.state;
        for (&v, aj) in tet.iter().zip(&a) {
            let v = v.get();
            let block = stiffness_block(aj, aj, volume, lambda, mu);
            let (Some(k), Some(m), Some(count), Some(vel)) = (
                s.vertex_tensors.get_mut(v),
                s.masses_kg.get_mut(v),
                s.live_tets.get_mut(v),
                s.velocity_m_s.get_mut(v),
            ) else {
                continue;
            };
            *count = count.saturating_sub(1);
            if *count == 0 {
                *k = [T::zero(); 9];
                *m = T::zero();
                *vel = [T::zero(); 3];
            } else {
                subtract_block(k, &block);
                *m -= share;
            }
        }
        for [j, l] in TET_EDGE_PAIRS {
            // `K_jl −= B(a_j, a_l)`, in whichever row the layout stores the
            // edge (as `K_lj` it takes `B(a_j, a_l)ᵀ = B(a_l, a_j)`).
            let (Some(vj), Some(vl), Some(aj), Some(al)) =
                (tet.get(j), tet.get(l), a.get(j), a.get(l))
            else {
                continue;
            };
            let block = stiffness_block(aj, al, volume, lambda, mu);
            let block: [T; 9] =
                core::array::from_fn(|e| block.get((e / 3, e % 3)).copied().unwrap_or(T::zero()));
            subtract_edge_block(
                s.edge_group_starts,
                s.edge_groups,
                vj.as_u32(),
                vl.as_u32(),
                &block,
            );
        }
        let triangles = self.table.tet_triangles().get(t.get());
        if let (true, Some(&triangles)) = (s.has_stvk_terms(), triangles) {
            let place = TetPlace {
                tet: t.as_u32(),
                vertices: tet.map(VertexIndex::as_u32),
                edges: edges.map(EdgeIndex::as_u32),
                triangles,
            };
            let terms = tet_terms(place.vertices, &a, volume, lambda, mu);
            terms.subtract_from(&place, &mut s.stvk_terms);
        }
        if let Some(alive) = s.tet_alive.get_mut(t.get()) {
            *alive = false;
        }
    }
}

/// `k −= block` for a row-major stored 3×3 tensor.
fn subtract_block<T: Real>(k: &mut [T; 9], block: &nalgebra::Matrix3<T>) {
    for (e, x) in k.iter_mut().enumerate() {
        if let Some(b) = block.get((e / 3, e % 3)) {
            *x -= *b;
        }
    }
}

/// What one cutting or tearing call did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CutReport {
    /// Tets removed by this call (hanging ones included).
    pub removed: u32,
    /// `true` if more tets qualified than the capacity allowed: call again
    /// next step (the scan finds them again, so nothing is lost).
    pub pending: bool,
}

/// Tearing thresholds (MODELS.md §3); `None` switches a criterion off.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TearThresholds<T> {
    /// Largest `|V − V₀| / V₀`.
    pub volume_change: Option<T>,
    /// Largest mean of the six `(l − l₀) / l₀`.
    pub mean_elongation: Option<T>,
    /// Largest single `(l − l₀) / l₀`.
    pub max_elongation: Option<T>,
}

impl<T: Real> TensorMassModel<'_, '_, T> {
    /// Current position of `vertex`, m (rest + displacement).
    fn position(&self, vertex: VertexIndex) -> Option<Vector3<T>> {
        let p = self.table.rest_positions().get(vertex.get())?;
        let u = self.state.displacement_m.get(vertex.get())?;
        Some(Vector3::new(p[0] + u[0], p[1] + u[1], p[2] + u[2]))
    }

    /// Removes every live tet the tool segment `a_m`–`b_m` (a point when
    /// equal) touches, at its current shape: a vertex within `radius_m` of
    /// the segment, or the segment passing through the tet (a blade longer
    /// than the tets cuts every tet along it, whatever the spacing of their
    /// vertices). At most `capacity` per call (Picinbono 2001 §3.1: the
    /// electric scalpel removes the tets it touches). Bounded: one scan of
    /// the tets.
    pub fn cut_with_tool(
        &mut self,
        a_m: Vector3<T>,
        b_m: Vector3<T>,
        radius_m: T,
        capacity: u32,
    ) -> CutReport {
        self.cut_reporting(a_m, b_m, radius_m, capacity, &mut |_| {})
    }

    /// [`Self::cut_with_tool`], telling `removed` each tet it removes.
    pub(super) fn cut_reporting(
        &mut self,
        a_m: Vector3<T>,
        b_m: Vector3<T>,
        radius_m: T,
        capacity: u32,
        removed: &mut dyn FnMut(TetIndex),
    ) -> CutReport {
        let axis = b_m - a_m;
        let length2 = axis.norm_squared();
        let r2 = radius_m * radius_m;
        let touches = |p: &Vector3<T>| {
            let t = if length2 > T::zero() {
                ((p - a_m).dot(&axis) / length2)
                    .max(T::zero())
                    .min(T::one())
            } else {
                T::zero()
            };
            (p - (a_m + axis * t)).norm_squared() <= r2
        };
        // The blade's box grown by the radius: a tet whose box misses it is
        // rejected on its 4 positions alone, the cheap test of the scan.
        let reach = [
            a_m.inf(&b_m).add_scalar(-radius_m),
            a_m.sup(&b_m).add_scalar(radius_m),
        ];
        self.remove_where(
            capacity,
            |model, tet| {
                let Some(now) = model.positions_of(tet) else {
                    return false;
                };
                let lo = now.iter().fold(now[0], |m, p| m.inf(p));
                let hi = now.iter().fold(now[0], |m, p| m.sup(p));
                let [r_lo, r_hi] = &reach;
                if (lo - r_hi).max() > T::zero() || (r_lo - hi).max() > T::zero() {
                    return false;
                }
                now.iter().any(touches) || crosses(&now, &a_m, &b_m)
            },
            removed,
        )
    }

    /// Removes every live tet past a [`TearThresholds`] criterion, at most
    /// `capacity` per call. Bounded: one scan of the tets.
    pub fn tear(&mut self, thresholds: &TearThresholds<T>, capacity: u32) -> CutReport {
        self.tear_reporting(thresholds, capacity, &mut |_| {})
    }

    /// [`Self::tear`], telling `removed` each tet it removes.
    pub(super) fn tear_reporting(
        &mut self,
        thresholds: &TearThresholds<T>,
        capacity: u32,
        removed: &mut dyn FnMut(TetIndex),
    ) -> CutReport {
        let thresholds = *thresholds;
        self.remove_where(
            capacity,
            move |model, tet| {
                model
                    .corners(tet)
                    .is_some_and(|(now, rest)| exceeds(&now, &rest, &thresholds))
            },
            removed,
        )
    }

    /// Current corner positions of `tet`, m.
    fn positions_of(&self, tet: [VertexIndex; 4]) -> Option<Corners<T>> {
        let mut now = [Vector3::zeros(); 4];
        for (n, &v) in now.iter_mut().zip(&tet) {
            *n = self.position(v)?;
        }
        Some(now)
    }

    /// Current and rest corner positions of `tet`, m.
    fn corners(&self, tet: [VertexIndex; 4]) -> Option<(Corners<T>, Corners<T>)> {
        let mut rest = [Vector3::zeros(); 4];
        for (r, &v) in rest.iter_mut().zip(&tet) {
            let p = self.table.rest_positions().get(v.get())?;
            *r = Vector3::new(p[0], p[1], p[2]);
        }
        Some((self.positions_of(tet)?, rest))
    }

    /// Scans the live tets in index order and removes those `qualifies`
    /// picks, up to `capacity`.
    fn remove_where(
        &mut self,
        capacity: u32,
        qualifies: impl Fn(&Self, [VertexIndex; 4]) -> bool,
        removed: &mut dyn FnMut(TetIndex),
    ) -> CutReport {
        let mut report = CutReport::default();
        for t in self.table.tet_indices() {
            let Some(tet) = self.table.tet_vertices(t) else {
                break;
            };
            if !self.is_alive(t) || !qualifies(self, tet) {
                continue;
            }
            if report.removed >= capacity {
                report.pending = true;
                break;
            }
            report.removed += self.remove(t, removed).unwrap_or(0);
        }
        report
    }
}

/// The four corner positions of a tet, m.
type Corners<T> = [Vector3<T>; 4];

/// `true` if the segment `a`–`b` has a point inside the tet with corners
/// `p` (m): the segment clipped by the 4 face half-spaces (Cyrus–Beck) is
/// not empty. A degenerate (flat or inverted) tet is never crossed.
fn crosses<T: Real>(p: &Corners<T>, a: &Vector3<T>, b: &Vector3<T>) -> bool {
    let (mut lo, mut hi) = (T::zero(), T::one());
    for j in 0..4 {
        // The face opposite corner j, its normal pointing towards j.
        let (Some(&o), Some(&f0), Some(&f1), Some(&f2)) = (
            p.get(j),
            p.get((j + 1) % 4),
            p.get((j + 2) % 4),
            p.get((j + 3) % 4),
        ) else {
            return false;
        };
        let mut n = (f1 - f0).cross(&(f2 - f0));
        let height = n.dot(&(o - f0));
        if height == T::zero() || !height.finite() {
            return false;
        }
        if height < T::zero() {
            n = -n;
        }
        let (da, db) = (n.dot(&(a - f0)), n.dot(&(b - f0)));
        if da < T::zero() && db < T::zero() {
            return false;
        }
        // Inside where n·(x − f0) ≥ 0 along x = a + t (b − a).
        if da < T::zero() {
            lo = lo.max(da / (da - db));
        } else if db < T::zero() {
            hi = hi.min(da / (da - db));
        }
    }
    lo <= hi
}

/// Signed volume of a tet, m³.
fn volume<T: Real>(p: &[Vector3<T>; 4]) -> T {
    let [p0, p1, p2, p3] = p;
    (p1 - p0).dot(&(p2 - p0).cross(&(p3 - p0))) / T::of_f64(6.0)
}

/// `true` if the tet with corners `now` (rest `rest`) passes a threshold.
fn exceeds<T: Real>(
    now: &[Vector3<T>; 4],
    rest: &[Vector3<T>; 4],
    thresholds: &TearThresholds<T>,
) -> bool {
    let v0 = volume(rest);
    let volume_change = ((volume(now) - v0) / v0).abs();
    let (mut sum, mut max) = (T::zero(), T::zero());
    for [j, k] in TET_EDGE_PAIRS {
        let (Some(a), Some(b), Some(a0), Some(b0)) =
            (now.get(j), now.get(k), rest.get(j), rest.get(k))
        else {
            continue;
        };
        let l0 = (b0 - a0).norm();
        let elongation = ((b - a).norm() - l0) / l0;
        sum += elongation;
        max = max.max(elongation);
    }
    let mean = sum / T::of_f64(6.0);
    // A NaN measure counts as past the limit.
    let past = |value: T, limit: Option<T>| {
        limit.is_some_and(|l| {
            matches!(
                value.partial_cmp(&l),
                Some(core::cmp::Ordering::Greater) | None
            )
        })
    };
    past(volume_change, thresholds.volume_change)
        || past(mean, thresholds.mean_elongation)
        || past(max, thresholds.max_elongation)
}

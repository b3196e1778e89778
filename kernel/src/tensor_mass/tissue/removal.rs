//! Blades and tearing at a physics update (module docs of the parent):
//! the tets removed, logged in removal order, and the surface's faces
//! brought up to them.

use super::{Blades, DynamicTissue};
use crate::Real;
use crate::math::Dispatch;
use crate::table::TetIndex;

impl<T: Real, const P: usize, D: Dispatch> DynamicTissue<'_, '_, T, P, D> {
    /// Removes what the blades touch, at most the cut capacity over all.
    pub(super) fn cut(&mut self, blades: &Blades<T>) {
        let capacity = self.physics.cut_capacity_tets;
        let mut left = capacity;
        let log = &mut self.removed;
        let mut record = |t: TetIndex| {
            // MAX_REMOVED_PER_UPDATE bounds what one update removes.
            let _ = log.push(t.as_u32());
        };
        for blade in blades {
            if left == 0 {
                break;
            }
            // The tissue ahead gives way once the sphere pushes it with the
            // cut force (the last update's held force along the normal).
            let pushing = self
                .held
                .get(blade.tool)
                .copied()
                .flatten()
                .is_some_and(|h| {
                    -h.contact.force_n.dot(&h.contact.normal) >= self.physics.cut_force_n
                });
            let pressed = blade
                .pressing
                .filter(|_| pushing)
                .and_then(|t| self.surface.tet_of(t));
            if let Some(t) = pressed.filter(|&t| self.model.is_alive(t)) {
                let n = self.model.remove(t, &mut record).unwrap_or(0);
                left = left.saturating_sub(n);
            }
            if left == 0 {
                break;
            }
            let report = self.model.cut_reporting(
                blade.from_m,
                blade.to_m,
                blade.radius_m,
                left,
                &mut record,
            );
            left = left.saturating_sub(report.removed);
        }
    }

    /// Brings the surface's faces up to the removals from entry `from` of
    /// the log on.
    pub(super) fn expose(&mut self, from: usize) {
        let table = *self.model.table();
        let removed = self.removed.get(from..).unwrap_or(&[]);
        self.surface.remove_tets(
            self.model.tet_alive(),
            removed.iter().filter_map(|&t| table.tet(t)),
        );
    }

    /// After the steps, the tets past the [`super::Tearing`] thresholds
    /// removed (at most its capacity, logged), and the surface's faces
    /// brought up to them.
    #[inline(always)]
    pub(super) fn tear(&mut self) {
        if let Some(tearing) = self.physics.tearing {
            let torn_from = self.removed.len();
            let log = &mut self.removed;
            self.model
                .tear_reporting(&tearing.thresholds, tearing.capacity_tets, &mut |t| {
                    let _ = log.push(t.as_u32());
                });
            self.expose(torn_from);
        }
    }
}

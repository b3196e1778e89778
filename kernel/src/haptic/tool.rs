//! What each tool point does in a tick (MODELS.md §6): a probe touches,
//! a grasper's jaw grips, a scalpel's blade cuts. The host maps its tools
//! onto these points (a grasper is two jaws, a cutter one blade).

use nalgebra::Vector3;

/// A tool point's action this tick.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum ToolAction<T> {
    /// A probe sphere: touches, slides without friction, pushes, and lets
    /// go when it would pull.
    #[default]
    Touch,
    /// A closed grasper jaw: the contact it has in the tick the grip
    /// closes is held ([`crate::contact::Contact::grip_offset_m`]): the
    /// contact point follows the jaw in every direction and may pull, until
    /// the action is no longer `Grip` (the jaw opens) or its triangle
    /// leaves the surface (a cut or a tear). A jaw that closes on nothing
    /// touches like a probe and holds nothing until it opens and closes
    /// again.
    Grip,
    /// An enabled blade: the segment from the tool point to
    /// `point + blade_m` (m), as thick as the tool sphere. At each physics
    /// update a tissue that can cut removes the tets it touches
    /// ([`crate::tensor_mass::Blade`]); the sphere at the point is also a
    /// probe, so the hand feels the tissue ahead of the blade. On a tissue
    /// that cannot be cut it is a probe and the output says so
    /// ([`super::ForceOutput::cut_refused`]).
    Cut {
        /// From the tool point along the blade to its other end, m.
        blade_m: Vector3<T>,
    },
}

/// A tool point's input for one tick.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ToolInput<T> {
    /// The tool sphere's centre, m.
    pub position_m: Vector3<T>,
    /// What it does.
    pub action: ToolAction<T>,
}

impl<T> ToolInput<T> {
    /// A probe at `position_m` (m).
    pub fn touch(position_m: Vector3<T>) -> Self {
        Self {
            position_m,
            action: ToolAction::Touch,
        }
    }
}

//! Haptic sessions on a scene ([`crate::scene`]): the scene's model resolved and its tables
//! built ([`model`], with the build options of [`options`]), the stable step checked
//! ([`stability`]), what the loop is built from ([`setup`]), and `session run` ([`run`],
//! [`hybrid`] for the hybrid model).
//!
//! Data flow: [`crate::scene::Scene`] + [`crate::scene::Trajectory`] → [`model::SceneModel`] →
//! [`model::SceneTables`] → the kernel's haptic loop, tick by tick. [`tools`] expands each
//! tick's tool states into the kernel's tool points (a grasper is two jaws), and
//! [`tool_points`] turns their count into the kernel's const generic.

pub mod hybrid;
pub mod model;
pub mod options;
pub mod run;
pub mod serve;
pub mod setup;
pub mod stability;
pub mod tool_points;
pub mod tools;

//! `palpate chart`: the speed/accuracy study. Every model of the harness is
//! run on the same loaded body at several refinements and loads, measured
//! against the converged compressible neo-Hookean equilibrium ([`truth`]:
//! the Pareto fronts and the "cheapest within" tables) and against the
//! Newton St Venant-Kirchhoff equilibrium on the finest mesh (a second
//! column; [`crate::fem::newton`]) and timed; [`memory`] builds the
//! pre-computed tables of every compliance encoding for the memory/accuracy
//! chart; [`plot`] draws the charts, [`report`] writes the report.
//!
//! The body: the generated cylinder ([`cylinder_mesh`](crate::mesh::generate::cylinder_mesh), height
//! [`HEIGHT_M`], radius `H/5`, E = 5 kPa, ν = 0.4), base fixed, loaded on its
//! top face by dead loads, the consistent nodal loads of a traction over
//! the top face (`face`: the same continuous load on every mesh):
//! - **press**: a uniform axial traction of total `−F ẑ`, with the
//!   lateral imperfection [`PRESS_IMPERFECTION`] (so past the buckling
//!   load every model bends the same way);
//! - **bend**: a uniform lateral traction of total `F x̂`;
//! - **twist**: the tangential traction `T (ẑ × r)/∫|r|² dA` (a torque `T`
//!   about the axis, `r` the distance vector from it).
//!
//! Each load has three levels: the force for which the linear FEM solution
//! on the finest mesh has a top-face displacement ([`tip_m`]) of 1 %, 5 %
//! and 20 % of the height.
//!
//! Models: the pre-computed linear model (the linear FEM solution of the
//! load, `fem::static_solve`; its step is the compliance product `u = C f`
//! the kernel's pre-computed update does), the same with the
//! quasi-non-linear remap (Cotin 1999 TVCG §3, fitted by
//! [`crate::remap::fit`] on the St Venant-Kirchhoff compression sample of
//! the same material and aspect), and the tensor-mass models (linear, St
//! Venant-Kirchhoff, St Venant-Kirchhoff + incompressibility penalty)
//! relaxed to rest by [`crate::experiment::relax`].
//!
//! Bounded: at most [`FULL_MESHES`] × 3 loads × [`LEVELS`] × 5 models
//! (135) static runs of at most [`MAX_RELAX_STEPS`] steps each, and the
//! stability map's [`stability`] trials.

pub mod memory;
pub mod plot;
pub mod report;
pub mod select;
pub mod series;
pub mod stability;
pub mod svg_text;
pub mod ticks;
pub mod trajectory;
pub mod truth;

mod body;
mod dynamic;
mod face;
mod matrix;
mod measure;
mod model;
mod precomputed;
mod preflight;
mod progress;
mod reference;
mod results;
mod study;
mod tables;

pub use body::{
    Body, GivenMesh, HEIGHT_M, HYBRID_DYNAMIC_FRACTION, LOADED_FACE_DEPTH, Load,
    PRESS_IMPERFECTION, tip_m,
};
pub use dynamic::RELAX_TOLERANCE;
pub use matrix::{
    FULL_MESHES, FULL_TRUTH, LEVELS, MAX_RELAX_STEPS, Matrix, QUICK_LEVELS, QUICK_MESHES,
    QUICK_RELAX_STEPS, QUICK_TRUTH, seconds_per_tet_step,
};
pub use model::{HYBRID_LAW, Model};
pub use preflight::preflight;
pub use progress::Progress;
pub use results::{Reference, Run, Study};
pub use study::run;

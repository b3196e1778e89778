//! The quasi-non-linear pre-computed model's remaps (Cotin 1999, TVCG §3;
//! MODELS.md §7), fitted on the host: [`curves`] reads or writes a
//! compression test's force/axial/radial curves, [`sample`] generates them
//! from a St Venant-Kirchhoff compression of a cylinder sample (and the
//! linear response of the same sample, the remaps' inputs), [`fit`] fits the
//! kernel's [`palpate_kernel::precomputed::Remap`] polynomials by least
//! squares.

pub mod curves;
pub mod fit;
pub mod sample;

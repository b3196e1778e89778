//! Files the harness writes for people and other tools: VTK series for
//! ParaView; [`atomic`]: how every output is written (whole or not at all);
//! [`stderr`]: the diagnostics, which never stop a run; [`number`]: how
//! values appear in messages.

pub mod atomic;
pub mod number;
pub mod stderr;
pub mod vtk;

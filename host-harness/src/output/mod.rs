//! Files the harness writes for people and other tools: VTK series for
//! ParaView; [`atomic`]: how every output is written (whole or not at all).

pub mod atomic;
pub mod vtk;

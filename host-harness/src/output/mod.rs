//! Files the harness writes for people and other tools: VTK series for ParaView.

pub mod vtk;

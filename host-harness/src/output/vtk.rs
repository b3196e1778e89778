//! Legacy VTK unstructured grids and a ParaView `.pvd` collection.
//!
//! Hand-written rather than through `vtkio`: the legacy ASCII writer is a few
//! lines, and vtkio 0.6 pulls in `nom` 3, which the compiler already flags as
//! rejected by future Rust versions.

use core::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::Context;

/// Writes one frame: the deformed mesh (`rest + displacement`, m) with the
/// displacement as point data.
pub fn write_frame(
    path: &Path,
    rest: &[[f64; 3]],
    tets: &[[u32; 4]],
    displacement_m: &[[f64; 3]],
) -> anyhow::Result<()> {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# vtk DataFile Version 3.0\npalpate frame\nASCII\nDATASET UNSTRUCTURED_GRID"
    );
    let _ = writeln!(s, "POINTS {} double", rest.len());
    for (p, u) in rest.iter().zip(displacement_m) {
        let _ = writeln!(s, "{} {} {}", p[0] + u[0], p[1] + u[1], p[2] + u[2]);
    }
    let _ = writeln!(s, "CELLS {} {}", tets.len(), tets.len() * 5);
    for t in tets {
        let _ = writeln!(s, "4 {} {} {} {}", t[0], t[1], t[2], t[3]);
    }
    let _ = writeln!(s, "CELL_TYPES {}", tets.len());
    for _ in tets {
        s.push_str("10\n");
    }
    let _ = writeln!(s, "POINT_DATA {}\nVECTORS displacement double", rest.len());
    for u in displacement_m {
        let _ = writeln!(s, "{} {} {}", u[0], u[1], u[2]);
    }
    std::fs::write(path, s).with_context(|| format!("{}: cannot write", path.display()))
}

/// Writes a ParaView collection listing `frames` as `(time in s, file)`.
pub fn write_collection(path: &Path, frames: &[(f64, PathBuf)]) -> anyhow::Result<()> {
    let mut s = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n",
    );
    for (t, file) in frames {
        let name = file
            .file_name()
            .map(|n| n.to_string_lossy())
            .unwrap_or_default();
        let _ = writeln!(s, "<DataSet timestep=\"{t}\" file=\"{name}\"/>");
    }
    s.push_str("</Collection>\n</VTKFile>\n");
    std::fs::write(path, s).with_context(|| format!("{}: cannot write", path.display()))
}

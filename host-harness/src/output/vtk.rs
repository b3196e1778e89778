//! Legacy VTK unstructured grids and a ParaView `.pvd` collection.
//!
//! Hand-written rather than through `vtkio`: the legacy ASCII writer is a few
//! lines, and vtkio 0.6 pulls in `nom` 3, which the compiler already flags as
//! rejected by future Rust versions.

use core::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};

use anyhow::Context;

use super::atomic::AtomicFile;

/// Writes one frame of a run's state ([`write_frame`]): the f32 displacement
/// field `u` (m, per vertex of `rest`; zero where missing) on the tets
/// `alive` keeps (all of `tets` without it, or when none is removed).
pub fn write_state_frame(
    path: &Path,
    rest: &[[f64; 3]],
    tets: &[[u32; 4]],
    u: &[[f32; 3]],
    alive: Option<&[bool]>,
) -> anyhow::Result<()> {
    let u: Vec<[f64; 3]> = (0..rest.len())
        .map(|v| u.get(v).map_or([0.0; 3], |d| d.map(f64::from)))
        .collect();
    let live: Vec<[u32; 4]>;
    let tets = match alive {
        Some(alive) if alive.contains(&false) => {
            live = tets
                .iter()
                .zip(alive)
                .filter(|(_, a)| **a)
                .map(|(t, _)| *t)
                .collect();
            &live
        }
        _ => tets,
    };
    write_frame(path, rest, tets, &u)
}

/// Writes one frame: the deformed mesh (`rest + displacement`, m) with the
/// displacement as point data.
pub fn write_frame(
    path: &Path,
    rest: &[[f64; 3]],
    tets: &[[u32; 4]],
    displacement_m: &[[f64; 3]],
) -> anyhow::Result<()> {
    let points: Vec<[f64; 3]> = rest
        .iter()
        .zip(displacement_m)
        .map(|(p, u)| [p[0] + u[0], p[1] + u[1], p[2] + u[2]])
        .collect();
    let mut s = unstructured_grid("palpate frame", &points, tets);
    let _ = writeln!(s, "POINT_DATA {}\nVECTORS displacement double", rest.len());
    for u in displacement_m {
        let _ = writeln!(s, "{} {} {}", u[0], u[1], u[2]);
    }
    std::fs::write(path, s).with_context(|| format!("{}: cannot write", path.display()))
}

/// Writes the rest mesh with the integer cell field `region` (one value per
/// tet: the hybrid partition's region ids, `palpate scene plan --vtk`),
/// atomically ([`AtomicFile`]).
pub fn write_regions(
    path: &Path,
    positions: &[[f64; 3]],
    tets: &[[u32; 4]],
    region: &[u32],
) -> anyhow::Result<()> {
    let mut s = unstructured_grid("palpate regions", positions, tets);
    let _ = writeln!(
        s,
        "CELL_DATA {}\nSCALARS region int 1\nLOOKUP_TABLE default",
        region.len()
    );
    for r in region {
        let _ = writeln!(s, "{r}");
    }
    let mut file = AtomicFile::create(path)?;
    file.write_all(s.as_bytes())?;
    file.commit()?;
    Ok(())
}

/// A legacy ASCII unstructured grid of linear tets (VTK cell type 10) at
/// `points` (m), titled `title`, before any point or cell data.
fn unstructured_grid(title: &str, points: &[[f64; 3]], tets: &[[u32; 4]]) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# vtk DataFile Version 3.0\n{title}\nASCII\nDATASET UNSTRUCTURED_GRID"
    );
    let _ = writeln!(s, "POINTS {} double", points.len());
    for p in points {
        let _ = writeln!(s, "{} {} {}", p[0], p[1], p[2]);
    }
    let _ = writeln!(s, "CELLS {} {}", tets.len(), tets.len() * 5);
    for t in tets {
        let _ = writeln!(s, "4 {} {} {} {}", t[0], t[1], t[2], t[3]);
    }
    let _ = writeln!(s, "CELL_TYPES {}", tets.len());
    for _ in tets {
        s.push_str("10\n");
    }
    s
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

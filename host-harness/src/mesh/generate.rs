//! Procedural meshes.

use super::TetMesh;
use super::validate::signed_volume;

/// A box `[0, size[0]] × [0, size[1]] × [0, size[2]]` (mesh units, m) split into
/// `cells[0] × cells[1] × cells[2]` cells of 6 Kuhn tets each.
///
/// Vertex `idx(i, j, k) = i + (nx+1)·(j + (ny+1)·k)` sits at `(i·(sx/nx), j·(sy/ny), k·(sz/nz))`.
/// Cells go x-fastest; in each cell, for the axis permutations (a,b,c) = (0,1,2), (0,2,1), (1,0,2),
/// (1,2,0), (2,0,1), (2,1,0) the tet is `[c0, c0+e_a, c0+e_a+e_b, c0+e_a+e_b+e_c]`, with the last two
/// vertices swapped where that tet would be negative. `box_mesh([5,5,5], [1.0; 3])` equals the
/// reference `cube` mesh exactly.
///
/// A zero cell count is treated as 1. `size` must be positive and finite and the vertex count must
/// fit `u32` for the result to satisfy the [`TetMesh`] invariants.
pub fn box_mesh(cells: [usize; 3], size: [f64; 3]) -> TetMesh {
    let [nx, ny, nz] = cells.map(|c| c.max(1));
    let h = [
        size[0] / nx as f64,
        size[1] / ny as f64,
        size[2] / nz as f64,
    ];
    let mut positions = Vec::with_capacity((nx + 1) * (ny + 1) * (nz + 1));
    for k in 0..=nz {
        for j in 0..=ny {
            for i in 0..=nx {
                positions.push([i as f64 * h[0], j as f64 * h[1], k as f64 * h[2]]);
            }
        }
    }
    let idx = |i: usize, j: usize, k: usize| (i + (nx + 1) * (j + (ny + 1) * k)) as u32;
    const PERMS: [[usize; 3]; 6] = [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
    ];
    let mut tets = Vec::with_capacity(nx * ny * nz * 6);
    for ck in 0..nz {
        for cj in 0..ny {
            for ci in 0..nx {
                for perm in PERMS {
                    let mut c = [ci, cj, ck];
                    let mut tet = [idx(c[0], c[1], c[2]); 4];
                    for (slot, axis) in tet.iter_mut().skip(1).zip(perm) {
                        c[axis] += 1;
                        *slot = idx(c[0], c[1], c[2]);
                    }
                    let p = |v: u32| positions[v as usize];
                    if signed_volume(p(tet[0]), p(tet[1]), p(tet[2]), p(tet[3])) < 0.0 {
                        tet.swap(2, 3);
                    }
                    tets.push(tet);
                }
            }
        }
    }
    TetMesh { positions, tets }
}

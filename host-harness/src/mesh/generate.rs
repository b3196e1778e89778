//! Procedural meshes: a box, a circular cylinder and a voxel-carved liver-like organ, all built
//! from the same Kuhn split of grid cells (the 6 tets per cell of [`box_mesh`]), so every mesh here
//! is conformal by construction.

use super::TetMesh;
use super::surface::boundary_surface;

/// The six axis orders of a Kuhn cell, each with whether it is an even permutation of (0, 1, 2).
const KUHN_PATHS: [([usize; 3], bool); 6] = [
    ([0, 1, 2], true),
    ([0, 2, 1], false),
    ([1, 0, 2], false),
    ([1, 2, 0], true),
    ([2, 0, 1], true),
    ([2, 1, 0], false),
];

/// The 6 Kuhn tets of the grid cell whose lowest grid corner is `cell`.
///
/// The walk starts at the cell corner `cell + flip` (per axis, the upper corner where `flip` is
/// set) and, for each axis order (a,b,c) of [`KUHN_PATHS`] in turn, steps one grid unit along a,
/// then b, then c (downward along flipped axes): the tet is the 4 grid points visited, mapped to
/// vertex indices by `vertex`. All 6 tets share the cell diagonal from the start corner to the
/// opposite corner, and every square face of the cell is split by its diagonal through the start
/// corner's projection; so cells with the same flips along a shared face's two in-plane axes meet
/// conformally. The last two vertices are swapped where the tet would be negative in grid
/// coordinates (sign = parity of the axis order × (−1)^flips), so the tets are positive for any
/// vertex placement that is an orientation-preserving map of the grid, and an inverted tet of a
/// curved placement shows up as a negative volume instead of being silently re-oriented.
fn kuhn_cell(
    cell: [usize; 3],
    flip: [bool; 3],
    vertex: impl Fn([usize; 3]) -> u32,
) -> [[u32; 4]; 6] {
    let start = [0, 1, 2].map(|a| cell[a] + usize::from(flip[a]));
    let odd_flips = flip.iter().filter(|&&f| f).count() % 2 == 1;
    KUHN_PATHS.map(|(order, even)| {
        let mut g = start;
        let mut tet = [vertex(g); 4];
        for (slot, axis) in tet.iter_mut().skip(1).zip(order) {
            if flip[axis] {
                g[axis] -= 1;
            } else {
                g[axis] += 1;
            }
            *slot = vertex(g);
        }
        if even == odd_flips {
            tet.swap(2, 3);
        }
        tet
    })
}

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
    let idx = |[i, j, k]: [usize; 3]| (i + (nx + 1) * (j + (ny + 1) * k)) as u32;
    let mut tets = Vec::with_capacity(nx * ny * nz * 6);
    for ck in 0..nz {
        for cj in 0..ny {
            for ci in 0..nx {
                tets.extend(kuhn_cell([ci, cj, ck], [false; 3], idx));
            }
        }
    }
    TetMesh { positions, tets }
}

/// Default `radial_cells` of [`cylinder_mesh`]: grid cells from the axis to the rim.
pub const CYLINDER_RADIAL_CELLS: usize = 3;
/// Default `height_cells` of [`cylinder_mesh`]. With [`CYLINDER_RADIAL_CELLS`] the default cylinder
/// has `(2·3+1)²·16 = 784` vertices and `(2·3)²·15·6 = 3240` tets, and its central cells are cubes
/// (grid step `R/3 = H/15` across and along the axis).
pub const CYLINDER_HEIGHT_CELLS: usize = 15;

/// A solid circular cylinder along +z from `z = 0` to `z = height_m`, radius `R = height_m / 5`,
/// axis through `(0, 0)` (mesh units, m).
///
/// Construction: a grid of `[-1, 1]² × [0, H]` with `n = 2·radial_cells` cells per side across and
/// `height_cells` cells along z; grid point `(i, j, k)` (vertex `i + (n+1)·(j + (n+1)·k)`) has
/// square coordinates `s = (2i/n − 1, 2j/n − 1)`, mapped to the disk by the elliptical grid mapping
/// `x = R·s_x·√(1 − s_y²/2)`, `y = R·s_y·√(1 − s_x²/2)`, at `z = H·(k/height_cells)`. The mapping
/// sends the square's boundary onto the circle `x² + y² = R²` (so the rim vertices lie on the
/// circle up to rounding and the cross-section is a polygon inscribed in it) and has a positive
/// Jacobian `(1 − (s_x² + s_y²)/2)/√((1 − s_x²/2)(1 − s_y²/2))` everywhere but the four square
/// corners. Cells (x-fastest, then y, then z) are split into the 6 Kuhn tets of [`box_mesh`],
/// reflected per quadrant of the square (walked from the upper x corner where `s_x < 0`, from the
/// upper y corner where `s_y < 0`) so the cell diagonals run away from the axis; the reflection
/// keeps the split conformal across the planes `s_x = 0` and `s_y = 0`, and puts the diagonal of
/// each corner cell through the corner, where the mapping flattens the cell, instead of across it
/// (which would give a near-flat triangle of three rim vertices: the smallest tet of the default
/// cylinder would be 0.29 of the mean volume instead of 0.567).
///
/// Volume: the cross-section is the polygon inscribed in the circle through the `8·radial_cells`
/// rim vertices, so the volume is `πR²H` less the chord error `(R²H/2)·Σ (Δθ_i − sin Δθ_i)` over
/// the rim's angular steps, at most `Δθ_max²/6` of `πR²H`; for the default counts (steps of 13.6°
/// to 16.9°) it is 1.167 % below `πR²H`.
///
/// Invariants: the [`TetMesh`] ones, every vertex used, the bottom face vertices at `z = 0.0`
/// exactly and the top ones at `z = height_m` exactly, `(n+1)²` vertices on each. A zero cell count
/// is treated as 1; `height_m` must be positive and finite.
pub fn cylinder_mesh(height_m: f64, radial_cells: usize, height_cells: usize) -> TetMesh {
    let r = radial_cells.max(1);
    let nz = height_cells.max(1);
    let n = 2 * r;
    let radius = height_m / 5.0;
    let square = |i: usize| (i as f64 - r as f64) / r as f64;
    let mut positions = Vec::with_capacity((n + 1) * (n + 1) * (nz + 1));
    for k in 0..=nz {
        let z = height_m * (k as f64 / nz as f64);
        for j in 0..=n {
            let sy = square(j);
            for i in 0..=n {
                let sx = square(i);
                positions.push([
                    radius * sx * (1.0 - sy * sy / 2.0).sqrt(),
                    radius * sy * (1.0 - sx * sx / 2.0).sqrt(),
                    z,
                ]);
            }
        }
    }
    let idx = |[i, j, k]: [usize; 3]| (i + (n + 1) * (j + (n + 1) * k)) as u32;
    let mut tets = Vec::with_capacity(n * n * nz * 6);
    for ck in 0..nz {
        for cj in 0..n {
            for ci in 0..n {
                tets.extend(kuhn_cell([ci, cj, ck], [ci < r, cj < r, false], idx));
            }
        }
    }
    TetMesh { positions, tets }
}

/// Default cube edge of [`organ_mesh`], m: `3/256 m ≈ 11.7 mm`. Being `3·2⁻⁸`, every vertex
/// coordinate and every Kuhn tet volume (`h³/6 = 9·2⁻²⁵ m³`) is exact in `f64`, so the mesh volume
/// equals the kept-cube count times `h³` exactly.
pub const ORGAN_CUBE_M: f64 = 3.0 / 256.0;
/// Default `radius_m` of [`organ_underside_patch`], m.
pub const ORGAN_PATCH_RADIUS_M: f64 = 0.02;
/// Default `depth_m` of [`organ_left_lobe_tip`], m.
pub const ORGAN_LOBE_TIP_DEPTH_M: f64 = 0.03;

/// An ellipsoid of the organ shape: centre and semi-axes, m.
struct Ellipsoid {
    centre: [f64; 3],
    semi_axes: [f64; 3],
}

impl Ellipsoid {
    /// Approximate signed distance, m: `(|(p − c)/a| − 1)·min(a)` (negative inside, exact on the
    /// surface, within a factor `max(a)/min(a)` of the distance elsewhere).
    fn field(&self, p: [f64; 3]) -> f64 {
        let q = [0, 1, 2].map(|a| (p[a] - self.centre[a]) / self.semi_axes[a]);
        let scale = self.semi_axes.iter().copied().fold(f64::INFINITY, f64::min);
        ((q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt() - 1.0) * scale
    }
}

/// The right lobe: the large dome (x from −0.045 to 0.105 m, 0.15 m front to back, 0.1 m high above
/// the floor).
const RIGHT_LOBE: Ellipsoid = Ellipsoid {
    centre: [0.03, 0.0, 0.0],
    semi_axes: [0.075, 0.075, 0.065],
};
/// The left lobe: thinner (5.6 cm at most), higher, reaching x = −0.1 m.
const LEFT_LOBE: Ellipsoid = Ellipsoid {
    centre: [-0.045, 0.01, 0.012],
    semi_axes: [0.055, 0.055, 0.028],
};
/// Blend width of the smooth union of the lobes, m.
const LOBE_BLEND_M: f64 = 0.02;
/// The flat underside (visceral face): the shape keeps `z > ORGAN_FLOOR_Z_M`.
const ORGAN_FLOOR_Z_M: f64 = -0.035;

/// The organ's implicit function, m (negative inside): the polynomial smooth minimum (blend width
/// [`LOBE_BLEND_M`]) of the two lobe fields, intersected with the half-space above the floor.
fn organ_field(p: [f64; 3]) -> f64 {
    let (a, b) = (RIGHT_LOBE.field(p), LEFT_LOBE.field(p));
    let w = (LOBE_BLEND_M - (a - b).abs()).max(0.0) / LOBE_BLEND_M;
    let lobes = a.min(b) - w * w * LOBE_BLEND_M / 4.0;
    lobes.max(ORGAN_FLOOR_Z_M - p[2])
}

/// A liver-like organ (mesh units, m), voxel-carved from a smooth implicit shape by [`voxel_mesh`]
/// with cubes of edge `cube_m`.
///
/// Shape (x from the left lobe to the right lobe, y front to back, z up): the smooth union
/// (polynomial smooth minimum, blend width 2 cm) of a large right lobe, the ellipsoid centred at
/// (0.03, 0, 0) m with semi-axes (0.075, 0.075, 0.065) m, and a thinner, higher left lobe, centred
/// at (−0.045, 0.01, 0.012) m with semi-axes (0.055, 0.055, 0.028) m, cut flat below at
/// `z = −0.035` m (the underside): about 0.2 m × 0.15 m × 0.1 m, 1.6 L.
///
/// Invariants: those of [`voxel_mesh`]: every vertex used, `6 × kept cubes` tets, every tet of
/// volume `cube_m³/6` (so the volume is the kept-cube count times `cube_m³`, exactly so for
/// [`ORGAN_CUBE_M`]), face-connected, boundary closed and manifold. At the default
/// [`ORGAN_CUBE_M`]: 1386 vertices, 5868 tets (978 cubes), 1.574·10⁻³ m³, bounding box
/// 0.199 m × 0.141 m × 0.105 m, and the smooth shape needs no manifold repair (none from 25 mm
/// down to 6 mm cubes). `cube_m` must be positive and finite; the lattice has about
/// `(0.23 m / cube_m)³` cells.
pub fn organ_mesh(cube_m: f64) -> TetMesh {
    // The shape with a 1 cm margin (the blend bulges a few mm at most).
    voxel_mesh(
        cube_m,
        [
            [-0.11, -0.085, ORGAN_FLOOR_Z_M - 0.01],
            [0.115, 0.085, 0.075],
        ],
        |p| organ_field(p) < 0.0,
    )
}

/// A voxel-carved tet mesh (mesh units, m) of the set where `inside` holds, within `bounds`
/// (`[min corner, max corner]`).
///
/// Construction: the cubes of edge `cube_m` of the lattice `cube_m·ℤ³` that overlap `bounds` and
/// whose centre is inside are kept; then, until nothing changes, cubes are removed wherever the
/// 2×2×2 cubes around a lattice vertex are not face-connected among themselves, or their empty
/// cubes are not, or two kept cubes meet across an edge with the other two empty; this removes
/// edge-only and vertex-only contacts and pinches and leaves a boundary that is a 2-manifold
/// (smooth shapes resolved by the lattice need no removal). Then only the largest face-connected
/// component is kept (ties: the one with the lowest cube in x-fastest order), which keeps that
/// property. Every kept cube, in x-fastest lattice order, is split into the 6 Kuhn tets of
/// [`box_mesh`], with the same diagonal in every cube, so neighbouring cubes meet conformally.
/// Vertices are the corners of kept cubes, numbered in x-fastest lattice order, at
/// `(i·cube_m, j·cube_m, k·cube_m)` for integers `i, j, k`.
///
/// Invariants: the [`TetMesh`] ones (if some cube centre is inside; otherwise there are no tets),
/// every vertex used, `tets.len() = 6 × kept cubes`, every tet of volume `cube_m³/6`,
/// face-connected, boundary surface closed with every boundary edge in exactly two boundary
/// triangles and every boundary vertex's triangles forming one fan. `cube_m` must be positive and
/// finite and the lattice box small enough to allocate.
pub fn voxel_mesh(
    cube_m: f64,
    bounds: [[f64; 3]; 2],
    inside: impl Fn([f64; 3]) -> bool,
) -> TetMesh {
    let lo = bounds[0].map(|x| (x / cube_m).floor() as isize);
    let hi = bounds[1].map(|x| (x / cube_m).ceil() as isize);
    let n = [0, 1, 2].map(|a| (hi[a] - lo[a]).max(0) as usize);
    let mut voxels = Voxels {
        n,
        kept: Vec::with_capacity(n[0] * n[1] * n[2]),
    };
    for k in 0..n[2] {
        for j in 0..n[1] {
            for i in 0..n[0] {
                let centre = [i, j, k].map(|x| x as f64 + 0.5);
                voxels.kept.push(inside(
                    [0, 1, 2].map(|a| (lo[a] as f64 + centre[a]) * cube_m),
                ));
            }
        }
    }
    voxels.make_manifold();
    voxels.keep_largest_component();
    // Vertices: corners of kept cubes, renumbered densely in lattice order.
    let nv = [n[0] + 1, n[1] + 1, n[2] + 1];
    let lattice = |[i, j, k]: [usize; 3]| i + nv[0] * (j + nv[1] * k);
    let mut used = vec![false; nv[0] * nv[1] * nv[2]];
    for (c, _) in voxels.kept.iter().enumerate().filter(|(_, k)| **k) {
        let g = [c % n[0], (c / n[0]) % n[1], c / (n[0] * n[1])];
        for b in 0..8 {
            used[lattice([g[0] + (b & 1), g[1] + (b >> 1 & 1), g[2] + (b >> 2 & 1)])] = true;
        }
    }
    let mut number = vec![u32::MAX; used.len()];
    let mut positions = Vec::new();
    for k in 0..nv[2] {
        for j in 0..nv[1] {
            for i in 0..nv[0] {
                let v = lattice([i, j, k]);
                if used[v] {
                    number[v] = positions.len() as u32;
                    positions.push([
                        (lo[0] + i as isize) as f64 * cube_m,
                        (lo[1] + j as isize) as f64 * cube_m,
                        (lo[2] + k as isize) as f64 * cube_m,
                    ]);
                }
            }
        }
    }
    let mut tets = Vec::new();
    for (c, _) in voxels.kept.iter().enumerate().filter(|(_, k)| **k) {
        let g = [c % n[0], (c / n[0]) % n[1], c / (n[0] * n[1])];
        tets.extend(kuhn_cell(g, [false; 3], |v| number[lattice(v)]));
    }
    TetMesh { positions, tets }
}

/// A small patch of the organ's flat underside, for fixing: the vertices of `mesh` on its lowest
/// plane (`z` equal to the minimum `z`) within horizontal distance `radius_m` (m) of the point
/// below the right lobe's centre, `(0.03, 0)` m. Ascending vertex indices.
///
/// Meant for a mesh from [`organ_mesh`], whose lowest plane is the flat underside; with
/// [`ORGAN_PATCH_RADIUS_M`] and [`ORGAN_CUBE_M`] it holds 8 vertices.
pub fn organ_underside_patch(mesh: &TetMesh, radius_m: f64) -> Vec<u32> {
    let z_min = mesh
        .positions
        .iter()
        .map(|p| p[2])
        .fold(f64::INFINITY, f64::min);
    let [cx, cy, _] = RIGHT_LOBE.centre;
    (0..mesh.positions.len() as u32)
        .filter(|&v| {
            let [x, y, z] = mesh.positions[v as usize];
            z == z_min && (x - cx).hypot(y - cy) <= radius_m
        })
        .collect()
}

/// The tip of the organ's left lobe, for loading: the boundary-surface vertices of `mesh` with `x`
/// within `depth_m` (m) of the minimum `x` of the mesh (the left lobe reaches furthest in −x).
/// Ascending vertex indices.
///
/// Meant for a mesh from [`organ_mesh`]; with [`ORGAN_LOBE_TIP_DEPTH_M`] the region is the last
/// 3 cm of the left lobe (83 vertices at [`ORGAN_CUBE_M`]), well away from
/// [`organ_underside_patch`] (which lies at `x ≥ 0.01` m for radii up to 2 cm).
pub fn organ_left_lobe_tip(mesh: &TetMesh, depth_m: f64) -> Vec<u32> {
    let x_min = mesh
        .positions
        .iter()
        .map(|p| p[0])
        .fold(f64::INFINITY, f64::min);
    boundary_surface(mesh)
        .vertices
        .into_iter()
        .filter(|&v| mesh.positions[v as usize][0] <= x_min + depth_m)
        .collect()
}

/// A set of lattice cubes on a box of `n[0] × n[1] × n[2]` cells, x-fastest.
struct Voxels {
    n: [usize; 3],
    kept: Vec<bool>,
}

impl Voxels {
    fn cell(&self, c: [usize; 3]) -> usize {
        c[0] + self.n[0] * (c[1] + self.n[1] * c[2])
    }

    /// Whether the cube at signed cell coordinates `c` is kept (false outside the box).
    fn get(&self, c: [isize; 3]) -> bool {
        let inside = (0..3).all(|a| c[a] >= 0 && (c[a] as usize) < self.n[a]);
        inside && self.kept[self.cell(c.map(|x| x as usize))]
    }

    /// Remove cubes until [`block_is_manifold`] holds around every lattice vertex (then the
    /// boundary of the kept cubes is a 2-manifold). Bad blocks are repaired by [`repair_block`];
    /// sweeps repeat until one changes nothing (each change removes a cube, so this ends).
    fn make_manifold(&mut self) {
        let n = self.n.map(|x| x as isize);
        loop {
            let mut changed = false;
            for k in 0..=n[2] {
                for j in 0..=n[1] {
                    for i in 0..=n[0] {
                        // Cube `b = dx + 2·dy + 4·dz` of the block around vertex (i, j, k).
                        let at = |b: usize| {
                            [
                                i - 1 + (b & 1) as isize,
                                j - 1 + (b >> 1 & 1) as isize,
                                k - 1 + (b >> 2 & 1) as isize,
                            ]
                        };
                        let mask = (0..8).fold(0u8, |m, b| m | u8::from(self.get(at(b))) << b);
                        let removed = mask & !repair_block(mask);
                        for b in (0..8).filter(|b| removed >> b & 1 == 1) {
                            let c = self.cell(at(b).map(|x| x as usize));
                            self.kept[c] = false;
                            changed = true;
                        }
                    }
                }
            }
            if !changed {
                return;
            }
        }
    }

    /// Keep only the largest face-connected component (ties: the one holding the lowest cell).
    fn keep_largest_component(&mut self) {
        let mut label = vec![usize::MAX; self.kept.len()];
        let mut best = (0, usize::MAX);
        let mut stack = Vec::new();
        for seed in 0..self.kept.len() {
            if !self.kept[seed] || label[seed] != usize::MAX {
                continue;
            }
            label[seed] = seed;
            stack.push(seed);
            let mut size = 0;
            while let Some(c) = stack.pop() {
                size += 1;
                let g = [
                    c % self.n[0],
                    (c / self.n[0]) % self.n[1],
                    c / (self.n[0] * self.n[1]),
                ];
                for axis in 0..3 {
                    for step in [-1, 1] {
                        let mut h = g.map(|x| x as isize);
                        h[axis] += step;
                        if self.get(h) {
                            let d = self.cell(h.map(|x| x as usize));
                            if label[d] == usize::MAX {
                                label[d] = seed;
                                stack.push(d);
                            }
                        }
                    }
                }
            }
            if size > best.0 {
                best = (size, seed);
            }
        }
        for (k, l) in self.kept.iter_mut().zip(&label) {
            *k = *k && *l == best.1;
        }
    }
}

/// The face-connected component of `seed` among the cubes set in `mask`, within a 2×2×2 block (cube
/// `b = dx + 2·dy + 4·dz`; face neighbours differ in one bit).
fn block_component(mask: u8, seed: usize) -> u8 {
    let mut comp = 1u8 << seed;
    // Any two cubes of the block are at most 3 face steps apart.
    for _ in 0..3 {
        let reached = comp;
        for b in (0..8).filter(|b| reached >> b & 1 == 1) {
            for bit in [1, 2, 4] {
                comp |= (mask >> (b ^ bit) & 1) << (b ^ bit);
            }
        }
    }
    comp
}

/// The face-connected components of the cubes set in `mask` within a 2×2×2 block, each with its
/// lowest cube first found.
fn block_components(mask: u8) -> Vec<u8> {
    let mut comps: Vec<u8> = Vec::new();
    for seed in (0..8).filter(|s| mask >> s & 1 == 1) {
        if comps.iter().all(|c| c >> seed & 1 == 0) {
            comps.push(block_component(mask, seed));
        }
    }
    comps
}

/// Whether the kept cubes `mask` of the 2×2×2 block around a lattice vertex leave a manifold
/// boundary there: kept and empty cubes each face-connected within the block, and none of the 6
/// half-edges from the vertex surrounded by exactly two diagonally opposite kept cubes.
fn block_is_manifold(mask: u8) -> bool {
    let diagonal_edge = (0..3).any(|axis| {
        let (u, v) = (1u8 << ((axis + 1) % 3), 1u8 << ((axis + 2) % 3));
        [0u8, 1 << axis].iter().any(|&side| {
            let ring = [side, side | u, side | u | v, side | v].map(|b| mask >> b & 1);
            ring == [1, 0, 1, 0] || ring == [0, 1, 0, 1]
        })
    });
    !diagonal_edge && block_components(mask).len() <= 1 && block_components(!mask).len() <= 1
}

/// Remove kept cubes from `mask` until [`block_is_manifold`] holds (at worst all of them, which is
/// manifold): if the kept cubes are split, keep their largest block component (ties: the first
/// found); otherwise remove the kept cube face-adjacent to the most empty cubes (ties: the lowest),
/// which joins the empty cubes around it.
fn repair_block(mut mask: u8) -> u8 {
    while !block_is_manifold(mask) {
        let comps = block_components(mask);
        if comps.len() > 1 {
            mask = comps.iter().copied().fold(0, |best, c| {
                if c.count_ones() > best.count_ones() {
                    c
                } else {
                    best
                }
            });
        } else {
            let empty_neighbours = |b: usize| {
                [1, 2, 4]
                    .iter()
                    .filter(|&&bit| mask >> (b ^ bit) & 1 == 0)
                    .count()
            };
            let cut = (0..8)
                .filter(|&b| mask >> b & 1 == 1)
                .max_by_key(|&b| (empty_neighbours(b), core::cmp::Reverse(b)));
            if let Some(b) = cut {
                mask &= !(1 << b);
            }
        }
    }
    mask
}

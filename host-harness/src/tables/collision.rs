//! The collision index of a pre-computed table (Cotin 1999 §4, collision
//! buckets): the boundary-surface vertices filed in a regular grid, and the
//! surface triangles around each vertex. The kernel view and its checks are
//! `palpate_kernel::haptic::surface::SurfaceIndex`.

/// The index, ready to be written as sections.
#[derive(Clone, Debug, PartialEq)]
pub struct CollisionIndex {
    /// Grid origin `x, y, z` and cell edge, m.
    pub grid: [f64; 4],
    /// Cells per axis.
    pub dims: [u32; 3],
    /// CSR starts of each cell's vertices (cells + 1).
    pub cell_start: Vec<u32>,
    /// Surface vertices by cell, each once.
    pub grid_vertex: Vec<u32>,
    /// CSR starts of each vertex's triangles (N + 1).
    pub vertex_triangle_start: Vec<u32>,
    /// Triangles around each vertex, ascending.
    pub vertex_triangle: Vec<u32>,
    /// Each triangle's unit outward normal and offset `n·p₀` (m).
    pub planes: Vec<[f64; 4]>,
}

/// Builds the index of the surface `triangles` over `positions` (m).
/// A triangle with a vertex outside `positions` (a corrupted input) is left
/// out of the grid and filed under the last vertex, which keeps the section
/// sizes, so the loader reports the triangle itself.
///
/// The cell edge is the longest surface edge: any point of a surface
/// triangle is then within one cell of each of its vertices, so the 27
/// cells around a point on (or just off) the surface hold every vertex of
/// the triangle it lies on. The edge is enlarged if needed so that there
/// are at most 8 cells per surface vertex.
pub fn collision_index(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> CollisionIndex {
    let n = positions.len();
    let mut on_surface = vec![false; n];
    let mut longest: f64 = 0.0;
    let valid = |tri: &&[u32; 3]| tri.iter().all(|&v| (v as usize) < n);
    for tri in triangles.iter().filter(valid) {
        for (a, b) in [(0, 1), (1, 2), (2, 0)] {
            let (p, q) = (positions[tri[a] as usize], positions[tri[b] as usize]);
            let d = ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt();
            longest = longest.max(d);
        }
        for &v in tri {
            on_surface[v as usize] = true;
        }
    }
    let surface: Vec<u32> = (0..n as u32).filter(|&v| on_surface[v as usize]).collect();
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for &v in &surface {
        for i in 0..3 {
            lo[i] = lo[i].min(positions[v as usize][i]);
            hi[i] = hi[i].max(positions[v as usize][i]);
        }
    }
    if surface.is_empty() {
        lo = [0.0; 3];
        hi = [0.0; 3];
    }
    let mut cell = if longest > 0.0 { longest } else { 1.0 };
    let dims = loop {
        let dims = [0, 1, 2].map(|i| (((hi[i] - lo[i]) / cell).floor() as u32).saturating_add(1));
        let cells = dims.iter().map(|&d| d as usize).product::<usize>();
        if cells <= 8 * surface.len().max(1) {
            break dims;
        }
        cell *= 1.25;
    };
    let cell_index = |p: [f64; 3]| {
        let c = [0, 1, 2].map(|i| (((p[i] - lo[i]) / cell).floor() as u32).min(dims[i] - 1));
        c[0] as usize + dims[0] as usize * (c[1] as usize + dims[1] as usize * c[2] as usize)
    };
    let cells = dims.iter().map(|&d| d as usize).product::<usize>();
    let mut buckets: Vec<Vec<u32>> = vec![Vec::new(); cells];
    for &v in &surface {
        buckets[cell_index(positions[v as usize])].push(v);
    }
    let (cell_start, grid_vertex) = csr(&buckets);
    let mut around: Vec<Vec<u32>> = vec![Vec::new(); n];
    for (t, tri) in triangles.iter().enumerate() {
        for &v in tri {
            let slot = (v as usize).min(n.saturating_sub(1));
            if let Some(list) = around.get_mut(slot) {
                list.push(t as u32);
            }
        }
    }
    let (vertex_triangle_start, vertex_triangle) = csr(&around);
    let planes = triangles
        .iter()
        .map(|tri| {
            let p = |i: usize| positions.get(tri[i] as usize).copied().unwrap_or([0.0; 3]);
            let (a, b, c) = (p(0), p(1), p(2));
            let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
            let n = [
                u[1] * v[2] - u[2] * v[1],
                u[2] * v[0] - u[0] * v[2],
                u[0] * v[1] - u[1] * v[0],
            ];
            let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            let n = if len > 0.0 {
                n.map(|x| x / len)
            } else {
                [0.0; 3]
            };
            [n[0], n[1], n[2], n[0] * a[0] + n[1] * a[1] + n[2] * a[2]]
        })
        .collect();
    CollisionIndex {
        planes,
        grid: [lo[0], lo[1], lo[2], cell],
        dims,
        cell_start,
        grid_vertex,
        vertex_triangle_start,
        vertex_triangle,
    }
}

/// Row starts and concatenated rows.
fn csr(rows: &[Vec<u32>]) -> (Vec<u32>, Vec<u32>) {
    let mut starts = Vec::with_capacity(rows.len() + 1);
    let mut items = Vec::new();
    starts.push(0);
    for row in rows {
        items.extend_from_slice(row);
        starts.push(items.len() as u32);
    }
    (starts, items)
}

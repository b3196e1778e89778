//! The elastic force of the tensor-mass model (MODELS.md §1):
//! `f_i = −(K_ii u_i + Σ_j K_ij u_j)`, one pass over the vertices and one over
//! the edges (each edge stored once, `K_ji = K_ijᵀ`).

use nalgebra::{Matrix3, Vector3};

use crate::Real;

/// The stiffness the force pass reads: current tensors and the CSR edge list.
pub(crate) struct Stiffness<'t, T> {
    pub(crate) vertex_tensors: &'t [[T; 9]],
    pub(crate) edge_tensors: &'t [[T; 9]],
    pub(crate) row_start: &'t [u32],
    pub(crate) column: &'t [u32],
}

/// `[T; 3]` as a vector.
pub(crate) fn vec3<T: Real>(v: &[T; 3]) -> Vector3<T> {
    Vector3::new(v[0], v[1], v[2])
}

impl<T: Real> Stiffness<'_, T> {
    /// Overwrites `f` with the elastic forces (N) of displacements `u` (m).
    /// Loops: `N` vertices, then `E` edges (lengths validated at load and at
    /// state construction; an out-of-range access is skipped, never a panic).
    pub(crate) fn elastic_forces(&self, u: &[[T; 3]], f: &mut [[T; 3]]) {
        for ((fi, ui), k) in f.iter_mut().zip(u).zip(self.vertex_tensors) {
            *fi = (-(Matrix3::from_row_slice(k) * vec3(ui))).into();
        }
        for (i, pair) in self.row_start.windows(2).enumerate() {
            let (Some(&[start, end]), Some(ui)) = (pair.first_chunk::<2>(), u.get(i)) else {
                continue;
            };
            let range = start as usize..end as usize;
            let (Some(columns), Some(tensors)) =
                (self.column.get(range.clone()), self.edge_tensors.get(range))
            else {
                continue;
            };
            let ui = vec3(ui);
            let mut fi = Vector3::zeros();
            for (&j, k) in columns.iter().zip(tensors) {
                let (Some(uj), Some(fj)) = (u.get(j as usize), f.get_mut(j as usize)) else {
                    continue;
                };
                let k = Matrix3::from_row_slice(k);
                fi -= k * vec3(uj);
                *fj = (vec3(fj) - k.tr_mul(&ui)).into();
            }
            if let Some(f) = f.get_mut(i) {
                *f = (vec3(f) + fi).into();
            }
        }
    }
}

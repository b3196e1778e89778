//! The linear P1 tetrahedron (`MODELS.md` §1; Cotin RR-3510 §4).

use nalgebra::Vector3;
use palpate_kernel::math::element::stiffness_block;

use super::material::Material;

/// Shape-function gradients and signed volume of the tetrahedron `p` (m).
///
/// Returns `(a, V)` with `a[j] = ∇Λ_j` (1/m), constant over the element, and
/// `V = det[p1-p0, p2-p0, p3-p0] / 6` (m³, positive for a positively oriented
/// tet). With `D = [p1-p0, p2-p0, p3-p0]` (columns), `a_1..a_3` are the rows of
/// `D⁻¹` and `a_0 = -(a_1 + a_2 + a_3)` (`MODELS.md` §1; `a_j = ±M_j / 6V`
/// with `M_j` the area vector of the face opposite `j`).
///
/// A degenerate tet (`V == 0`) gives non-finite gradients; meshes are
/// validated before they get here.
pub fn shape_gradients(p: &[[f64; 3]; 4]) -> ([[f64; 3]; 4], f64) {
    let [p0, p1, p2, p3] = p.map(Vector3::from);
    let (c1, c2, c3) = (p1 - p0, p2 - p0, p3 - p0);
    let (r1, r2, r3) = (c2.cross(&c3), c3.cross(&c1), c1.cross(&c2));
    let det = c1.dot(&r1);
    let inv = 1.0 / det;
    let (a1, a2, a3) = (r1 * inv, r2 * inv, r3 * inv);
    let a0 = -(a1 + a2 + a3);
    ([a0, a1, a2, a3].map(Into::into), det / 6.0)
}

/// Element stiffness of the tetrahedron `p` (m) for material `m`, as 4×4
/// blocks of 3×3 in N/m: `K[j][k][a][b] = ∂f_{j,a}/∂u_{k,b}` with the sign
/// convention `f_j = -Σ_k K_jk u_k` (elastic force on vertex `j`).
///
/// Each block is the kernel's [`stiffness_block`] (`MODELS.md` §1), the Hessian
/// of the strain energy `W = |V| (λ/2 (tr ε)² + μ ε:ε)`, so host assembly and
/// kernel tet removal use one formula. Using `|V|` makes the result
/// independent of the vertex orientation.
pub fn element_stiffness(p: &[[f64; 3]; 4], m: &Material) -> [[[[f64; 3]; 3]; 4]; 4] {
    let (a, v) = shape_gradients(p);
    let a = a.map(Vector3::from);
    let (lambda, mu) = m.lame();
    core::array::from_fn(|j| {
        core::array::from_fn(|k| {
            let block = stiffness_block(&a[j], &a[k], v.abs(), lambda, mu);
            core::array::from_fn(|r| core::array::from_fn(|c| block[(r, c)]))
        })
    })
}

//! The linear P1 tetrahedron (`MODELS.md` §1; Cotin RR-3510 §4).

use nalgebra::Vector3;
use palpate_kernel::math::element::stiffness_block;

use super::material::Material;

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

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
    let c1 = sub(p[1], p[0]);
    let c2 = sub(p[2], p[0]);
    let c3 = sub(p[3], p[0]);
    let r1 = cross(c2, c3);
    let r2 = cross(c3, c1);
    let r3 = cross(c1, c2);
    let det = dot(c1, r1);
    let inv = 1.0 / det;
    let a1 = r1.map(|x| x * inv);
    let a2 = r2.map(|x| x * inv);
    let a3 = r3.map(|x| x * inv);
    let a0 = [
        -(a1[0] + a2[0] + a3[0]),
        -(a1[1] + a2[1] + a3[1]),
        -(a1[2] + a2[2] + a3[2]),
    ];
    ([a0, a1, a2, a3], det / 6.0)
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

//! Products of a row-major 3×3 block with a 3-vector, generic over what
//! the entries are: scalars ([`crate::Real`]) or vector lanes holding one
//! entry of several blocks each (the tensor-mass model's edge groups).

use core::ops::{Add, Mul};

/// `K x` for a row-major 3×3 `K`, of scalars or of lanes.
#[inline(always)]
pub(crate) fn mul<S: Copy + Add<Output = S> + Mul<Output = S>>(k: &[S; 9], x: &[S; 3]) -> [S; 3] {
    [
        k[0] * x[0] + k[1] * x[1] + k[2] * x[2],
        k[3] * x[0] + k[4] * x[1] + k[5] * x[2],
        k[6] * x[0] + k[7] * x[1] + k[8] * x[2],
    ]
}

/// `Kᵀ x` for a row-major 3×3 `K`, of scalars or of lanes.
#[inline(always)]
pub(crate) fn mul_transposed<S: Copy + Add<Output = S> + Mul<Output = S>>(
    k: &[S; 9],
    x: &[S; 3],
) -> [S; 3] {
    [
        k[0] * x[0] + k[3] * x[1] + k[6] * x[2],
        k[1] * x[0] + k[4] * x[1] + k[7] * x[2],
        k[2] * x[0] + k[5] * x[1] + k[8] * x[2],
    ]
}

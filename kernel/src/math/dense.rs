//! Dense vector kernels over contiguous rows (the hybrid model's condensed
//! interface, RR-3510 §6.2), written with eight independent partial sums so
//! that they vectorize without reassociating one sum (which the compiler
//! may not do for floats on its own).

use super::Real;

/// Lanes of the partial sums.
const LANES: usize = 8;

/// `Σ_i a_i b_i` over the common prefix of `a` and `b`.
#[inline]
pub fn dot<T: Real>(a: &[T], b: &[T]) -> T {
    let mut acc = [T::zero(); LANES];
    let (a_chunks, a_rest) = a.as_chunks::<LANES>();
    let (b_chunks, b_rest) = b.as_chunks::<LANES>();
    for (x, y) in a_chunks.iter().zip(b_chunks) {
        for ((s, &x), &y) in acc.iter_mut().zip(x).zip(y) {
            *s += x * y;
        }
    }
    let rest = a_rest
        .iter()
        .zip(b_rest)
        .fold(T::zero(), |s, (&x, &y)| s + x * y);
    acc.iter().fold(rest, |s, &x| s + x)
}

/// `y_i += a x_i` over the common prefix of `x` and `y`.
#[inline]
pub fn axpy<T: Real>(a: T, x: &[T], y: &mut [T]) {
    for (y, &x) in y.iter_mut().zip(x) {
        *y += a * x;
    }
}

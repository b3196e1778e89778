//! Values in messages, bounded in length: Rust's `{}` writes an `f64`
//! without an exponent, so `1e300` is 301 digits and `5e-324` 326
//! characters. [`shown`] writes the shortest form that reads back the same
//! value, with an exponent outside `[1e-4, 1e15)` (integers of up to 15 digits stay plain): at most 24 characters.
//! [`time_s`] writes a time with nine significant digits (`2.264`, not the
//! accumulated `2.2640000000000002`).

use core::fmt;

/// `x` as [`shown`] writes it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shown(pub f64);

/// `x` for a message: `3000`, `0.45`, `1e300`, `5e-324`, `NaN`, `inf`.
pub fn shown(x: f64) -> Shown {
    Shown(x)
}

impl fmt::Display for Shown {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let x = self.0;
        let plain = x == 0.0 || !x.is_finite() || (1e-4..1e15).contains(&x.abs());
        if plain {
            write!(f, "{x}")
        } else {
            write!(f, "{x:e}")
        }
    }
}

/// A time, s, for a message: nine significant digits, trailing zeros
/// dropped, bounded as [`shown`] (`2.264`, `0.001`, `1e-12`).
pub fn time_s(t: f64) -> Shown {
    if !t.is_finite() || t == 0.0 {
        return Shown(t);
    }
    // `{:.8e}` rounds to nine significant digits; it reads back exactly.
    Shown(format!("{t:.8e}").parse().unwrap_or(t))
}

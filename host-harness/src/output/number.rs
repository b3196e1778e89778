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

#[cfg(test)]
mod tests {
    use super::*;

    /// Every class of value: its text, and the length bound.
    #[test]
    fn values_are_short_and_exact() {
        for (x, text) in [
            (3000.0, "3000"),
            (0.45, "0.45"),
            (0.49999999, "0.49999999"),
            (1e300, "1e300"),
            (-1e300, "-1e300"),
            (5e-324, "5e-324"),
            (1e-5, "1e-5"),
            (f64::NAN, "NaN"),
            (f64::INFINITY, "inf"),
            (0.0, "0"),
        ] {
            assert_eq!(shown(x).to_string(), text);
        }
        for x in [
            f64::MAX,
            f64::MIN,
            f64::MIN_POSITIVE,
            1.0 / 3.0,
            -1e6 / 3.0,
            12345678.9,
        ] {
            let text = shown(x).to_string();
            assert!(text.len() <= 24, "{text}");
            assert_eq!(text.parse::<f64>().expect("reads back"), x);
        }
    }

    /// The sum of 2264 ticks of 1 ms carries rounding: shown as 2.264.
    #[test]
    fn times_have_nine_significant_digits() {
        let t = (0..2264).fold(0.0f64, |t, _| t + 0.001);
        assert_ne!(t.to_string(), "2.264");
        assert_eq!(time_s(t).to_string(), "2.264");
        assert_eq!(time_s(2.2640000000000002).to_string(), "2.264");
        assert_eq!(time_s(1e-12).to_string(), "1e-12");
        assert_eq!(time_s(123.456789012).to_string(), "123.456789");
    }
}

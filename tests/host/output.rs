//! Numbers in messages (`palpate::output::number`): short, exact, bounded.

use palpate::output::number::{shown, time_s};

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

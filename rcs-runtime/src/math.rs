//! The language's float built-in functions (`sqrt`, `sin`, `min`, …), written
//! once. Generated controllers call these functions and the reference
//! interpreter (and the constant folder of `rcsc`) calls the same ones, so
//! both backends give bit-identical results on every input, NaN included.
//!
//! Everything is on `f64`; an `f32` argument is widened exactly with
//! `f64::from`, and the result is rounded back with `as f32`. (Calling the
//! `f32` methods instead would use different `libm` routines than the
//! interpreter, which carries `f32` values as `f64`.)
//!
//! NaN rule: NaN in, NaN out, for every function including `min`, `max` and
//! `clamp` (not IEEE 754 `minNum`, which would hide a NaN). `clamp` never
//! panics: `clamp(x, lo, hi)` is `max(min(x, hi), lo)`, so with `lo > hi` it
//! gives `lo`.

/// The smaller of two floats; NaN if either is NaN.
pub fn min(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.min(b)
    }
}

/// The larger of two floats; NaN if either is NaN.
pub fn max(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.max(b)
    }
}

/// `x` limited to `lo..=hi` as `max(min(x, hi), lo)`; NaN if any is NaN.
pub fn clamp(x: f64, lo: f64, hi: f64) -> f64 {
    max(min(x, hi), lo)
}

/// An integer `x` limited as `max(min(x, hi), lo)`: never panics (unlike
/// `Ord::clamp`, which does when `lo > hi`), and gives `lo` then.
#[inline]
#[allow(clippy::manual_clamp)] // `Ord::clamp` panics when lo > hi
pub fn clamp_int<T: Ord>(x: T, lo: T, hi: T) -> T {
    x.min(hi).max(lo)
}

/// `|x|`.
pub fn abs(x: f64) -> f64 {
    x.abs()
}

/// Square root; NaN below zero.
pub fn sqrt(x: f64) -> f64 {
    x.sqrt()
}

/// Sine (radians).
pub fn sin(x: f64) -> f64 {
    x.sin()
}

/// Cosine (radians).
pub fn cos(x: f64) -> f64 {
    x.cos()
}

/// Tangent (radians).
pub fn tan(x: f64) -> f64 {
    x.tan()
}

/// Arc sine; NaN outside -1..=1.
pub fn asin(x: f64) -> f64 {
    x.asin()
}

/// Arc cosine; NaN outside -1..=1.
pub fn acos(x: f64) -> f64 {
    x.acos()
}

/// Arc tangent.
pub fn atan(x: f64) -> f64 {
    x.atan()
}

/// The angle of the point `(x, y)`: `atan2(y, x)`.
pub fn atan2(y: f64, x: f64) -> f64 {
    y.atan2(x)
}

/// `e^x`.
pub fn exp(x: f64) -> f64 {
    x.exp()
}

/// Natural logarithm; NaN below zero, -inf at zero.
pub fn ln(x: f64) -> f64 {
    x.ln()
}

/// Largest integer value not above `x`.
pub fn floor(x: f64) -> f64 {
    x.floor()
}

/// Smallest integer value not below `x`.
pub fn ceil(x: f64) -> f64 {
    x.ceil()
}

/// Nearest integer value, halves away from zero (`round(-2.5) == -3.0`).
pub fn round(x: f64) -> f64 {
    x.round()
}

/// `sqrt(x² + y²)` without undue overflow.
pub fn hypot(x: f64, y: f64) -> f64 {
    x.hypot(y)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nan_in_nan_out() {
        assert!(min(f64::NAN, 1.0).is_nan());
        assert!(max(1.0, f64::NAN).is_nan());
        assert!(clamp(f64::NAN, 0.0, 1.0).is_nan());
        assert!(clamp(0.5, f64::NAN, 1.0).is_nan());
        assert!(sqrt(-1.0).is_nan());
    }

    #[test]
    fn clamp_never_panics_and_rounds_half_away() {
        assert_eq!(clamp(5.0, 2.0, 1.0), 2.0);
        assert_eq!(clamp_int(9i8, 3, 1), 3);
        assert_eq!(clamp_int(-9i8, -1, 1), -1);
        assert_eq!(clamp(-3.0, -1.0, 1.0), -1.0);
        assert_eq!(round(-2.5), -3.0);
        assert_eq!(round(2.5), 3.0);
    }
}

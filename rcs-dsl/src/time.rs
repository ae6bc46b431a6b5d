//! Time in seconds (LANGUAGE.md §8 "Time"): duration literals (`250us`,
//! `50ms`, `1.5s`) read to exact integer nanoseconds, and the arithmetic
//! that turns "elapsed time OP duration" into "cycles OP threshold" for a
//! CPU period, exactly (no rounding that fires early). Shared by the parser
//! (literals), the lowering (`lower::time`), the `timer_resolution` lint and
//! scenarios (`vars: { t: 50ms }`). Nothing here knows the IR.

use crate::ast::BinOp;

/// The units a duration literal may carry, with their size in nanoseconds.
pub const UNITS: [(&str, u64); 4] = [
    ("ns", 1),
    ("us", 1_000),
    ("ms", 1_000_000),
    ("s", 1_000_000_000),
];

/// Why a number with letters after it is not a duration.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum LiteralError {
    /// `5sec`, `3min`: the letters are no unit.
    UnknownUnit(String),
    /// `0x10ms`, `0b1s`: hex and binary are for integers only.
    NotDecimal,
    /// `1e3ms`: no exponent in a duration.
    Exponent,
    /// `1.0000000001s`: finer than a nanosecond.
    TooFine,
    /// Beyond `u64::MAX` nanoseconds (about 584 years).
    TooLong,
}

/// A number's text split at its unit: (`"1.5"`, `"s"`) for `1.5s`, the same
/// greedy reading as the grammar's `number` rule (digits, `.` digits, an
/// exponent, then letters). The unit is empty for a plain number.
pub fn split_unit(s: &str) -> (&str, &str) {
    let b = s.as_bytes();
    let mut i;
    if s.starts_with("0x") || s.starts_with("0b") {
        let hex = s.starts_with("0x");
        i = 2;
        while i < b.len()
            && (b[i] == b'_'
                || if hex {
                    b[i].is_ascii_hexdigit()
                } else {
                    b[i] == b'0' || b[i] == b'1'
                })
        {
            i += 1;
        }
        return s.split_at(i);
    }
    let digits = |mut i: usize| {
        while i < b.len() && (b[i].is_ascii_digit() || b[i] == b'_') {
            i += 1;
        }
        i
    };
    i = digits(0);
    if i + 1 < b.len() && b[i] == b'.' && b[i + 1].is_ascii_digit() {
        i = digits(i + 1);
    }
    if i < b.len() && (b[i] == b'e' || b[i] == b'E') {
        let mut j = i + 1;
        if j < b.len() && (b[j] == b'+' || b[j] == b'-') {
            j += 1;
        }
        if j < b.len() && b[j].is_ascii_digit() {
            i = digits(j);
        }
    }
    s.split_at(i)
}

/// A duration literal's value in nanoseconds: `number` is the part before
/// the unit (as [`split_unit`] gives it), `unit` the letters.
pub fn parse_literal(number: &str, unit: &str) -> Result<u64, LiteralError> {
    let Some(&(_, scale)) = UNITS.iter().find(|(u, _)| *u == unit) else {
        return Err(LiteralError::UnknownUnit(unit.to_string()));
    };
    if number.starts_with("0x") || number.starts_with("0b") {
        return Err(LiteralError::NotDecimal);
    }
    if number.contains(['e', 'E']) {
        return Err(LiteralError::Exponent);
    }
    let clean: String = number.chars().filter(|c| *c != '_').collect();
    let (whole, frac) = clean.split_once('.').unwrap_or((&clean, ""));
    let whole: u128 = whole.parse().map_err(|_| LiteralError::TooLong)?;
    let mut ns = whole
        .checked_mul(u128::from(scale))
        .ok_or(LiteralError::TooLong)?;
    // The fraction, digit by digit: each must land on a whole nanosecond.
    let mut place = u128::from(scale);
    for d in frac.bytes() {
        let digit = u128::from(d - b'0');
        if place % 10 != 0 {
            if digit != 0 {
                return Err(LiteralError::TooFine);
            }
            continue;
        }
        place /= 10;
        ns += digit * place;
    }
    u64::try_from(ns).map_err(|_| LiteralError::TooLong)
}

/// A duration for people, in the largest unit that writes it exactly:
/// `30ms`, `1.5s`, `250us`, `7ns`.
pub fn format_ns(ns: u64) -> String {
    if ns == 0 {
        return "0s".to_string();
    }
    for (unit, scale) in UNITS.iter().rev() {
        if ns >= *scale || *scale == 1 {
            let whole = ns / scale;
            let rest = ns % scale;
            if rest == 0 {
                return format!("{whole}{unit}");
            }
            let width = scale.ilog10() as usize;
            let frac = format!("{rest:0width$}");
            let frac = frac.trim_end_matches('0');
            // Keep to three decimals: finer reads better in the next unit.
            if frac.len() <= 3 {
                return format!("{whole}.{frac}{unit}");
            }
        }
    }
    format!("{ns}ns")
}

/// `elapsed OP duration`, with elapsed = cycles × `period_ns`, as a
/// comparison of the cycle count with a threshold: `(op, threshold)` such
/// that `cycles op threshold` holds exactly when `cycles × period op
/// duration` does, for every cycle count. `op` is `<`, `<=`, `>` or `>=`
/// (the caller refuses `==` and `!=`); `period_ns` is at least 1.
///
/// `c·p > d ⇔ c > ⌊d/p⌋`, `c·p >= d ⇔ c >= ⌈d/p⌉`, `c·p < d ⇔ c < ⌈d/p⌉`,
/// `c·p <= d ⇔ c <= ⌊d/p⌋`.
pub fn cycle_threshold(op: BinOp, duration_ns: u64, period_ns: u64) -> (BinOp, u64) {
    let floor = duration_ns / period_ns;
    let ceil = floor + u64::from(!duration_ns.is_multiple_of(period_ns));
    match op {
        BinOp::Gt | BinOp::Le => (op, floor),
        _ => (op, ceil),
    }
}

/// The first cycle count at which `cycles op threshold` holds (`>`, `>=`),
/// or the first at which it stops holding (`<`, `<=`): when a timeout
/// really fires, for the `timer_resolution` lint.
pub fn first_change(op: BinOp, threshold: u64) -> u64 {
    match op {
        BinOp::Gt | BinOp::Le => threshold.saturating_add(1),
        _ => threshold,
    }
}

/// `op` with its operands swapped: `5s < state_time` is `state_time > 5s`.
pub fn flipped(op: BinOp) -> BinOp {
    match op {
        BinOp::Lt => BinOp::Gt,
        BinOp::Le => BinOp::Ge,
        BinOp::Gt => BinOp::Lt,
        BinOp::Ge => BinOp::Le,
        other => other,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn literals_read_to_exact_nanoseconds() {
        let ns = |s: &str| {
            let (n, u) = split_unit(s);
            parse_literal(n, u)
        };
        assert_eq!(ns("250us"), Ok(250_000));
        assert_eq!(ns("50ms"), Ok(50_000_000));
        assert_eq!(ns("5s"), Ok(5_000_000_000));
        assert_eq!(ns("1.5s"), Ok(1_500_000_000));
        assert_eq!(ns("1_000ms"), Ok(1_000_000_000));
        assert_eq!(ns("0.25ms"), Ok(250_000));
        assert_eq!(ns("1.5000ns"), Err(LiteralError::TooFine));
        assert_eq!(ns("1.5ns"), Err(LiteralError::TooFine));
        assert_eq!(ns("5sec"), Err(LiteralError::UnknownUnit("sec".into())));
        assert_eq!(ns("0x10ms"), Err(LiteralError::NotDecimal));
        assert_eq!(ns("1e3ms"), Err(LiteralError::Exponent));
        assert_eq!(ns("99999999999s"), Err(LiteralError::TooLong));
        assert_eq!(split_unit("0x6F"), ("0x6F", ""));
        assert_eq!(split_unit("1.5e3"), ("1.5e3", ""));
        assert_eq!(split_unit("1.5e"), ("1.5", "e"));
    }

    #[test]
    fn durations_print_in_the_largest_exact_unit() {
        assert_eq!(format_ns(30_000_000), "30ms");
        assert_eq!(format_ns(1_500_000_000), "1.5s");
        assert_eq!(format_ns(250_000), "250us");
        assert_eq!(format_ns(7), "7ns");
        assert_eq!(format_ns(1_000_000_001), "1000000.001us");
    }

    /// The threshold agrees with the definition on every small case.
    #[test]
    fn thresholds_never_fire_early_nor_late() {
        for p in 1..=13u64 {
            for d in 0..=60u64 {
                for op in [BinOp::Lt, BinOp::Le, BinOp::Gt, BinOp::Ge] {
                    let (op2, k) = cycle_threshold(op, d, p);
                    for c in 0..=80u64 {
                        let want = match op {
                            BinOp::Lt => c * p < d,
                            BinOp::Le => c * p <= d,
                            BinOp::Gt => c * p > d,
                            _ => c * p >= d,
                        };
                        let got = match op2 {
                            BinOp::Lt => c < k,
                            BinOp::Le => c <= k,
                            BinOp::Gt => c > k,
                            _ => c >= k,
                        };
                        assert_eq!(want, got, "{c} cycles × {p} {op:?} {d}");
                    }
                }
            }
        }
    }
}

//! The arithmetic rules of docs/language.md ("Arithmetic", "Constants,
//! built-in functions and indexing") on the reference interpreter, on the
//! values that make them matter: division by zero, `MIN / -1`, saturating
//! and NaN casts, `abs` of MIN, NaN through `min` and past `<`/`>=`. The
//! plan is the ok case `0252_arithmetic.rcs`, which the differential test
//! also runs on the generated code, so both backends are held to these
//! values.

use rcs_dsl::interp::{HookData, Hooks, Interpreter, Value};
use rcs_dsl::ir::{CommandId, HookId, Ir};
use rcs_dsl::{check, Options, PlanSet};

const PLAN: &str = include_str!("../../tests/data/ok/0252_arithmetic.rcs");

struct NoHooks;
impl Hooks for NoHooks {
    fn call(&mut self, _: &HookData, _: HookId, _: &[Value]) -> Value {
        Value::Unit
    }
}

fn ir() -> Ir {
    let set = PlanSet::from_texts("arith", [("arith.rcs", PLAN)], None);
    check(&set, &Options::default()).ir.expect("checks clean")
}

/// Run the first cycle and the second (which decides) on input
/// `(a, b, x, small)`; the vars by name, and the row fired second.
fn run(a: i128, b: i128, x: f64, small: i128) -> (Vec<(String, Value)>, String) {
    let ir = ir();
    let mut interp = Interpreter::new(&ir, ir.controller_by_name("CALC").unwrap());
    interp.command(CommandId(0), vec![]);
    interp.set_read(
        0,
        Value::Buffer(vec![
            Value::Int(a),
            Value::Int(b),
            Value::Float(x),
            Value::Int(small),
        ]),
    );
    interp.cycle(&mut NoHooks);
    let second = interp.cycle(&mut NoHooks);
    let ctrl = interp.controller();
    let vars = ctrl
        .vars
        .iter()
        .map(|v| v.name.clone())
        .zip(interp.vars().iter().cloned())
        .collect();
    let fired = second
        .fired
        .map(|r| ctrl.plans[0].rows[r.index()].display_name())
        .unwrap_or_else(|| "none".into());
    (vars, fired)
}

fn var(vars: &[(String, Value)], name: &str) -> Value {
    vars.iter().find(|(n, _)| n == name).unwrap().1.clone()
}

#[test]
fn division_and_remainder_by_zero_give_zero() {
    let (vars, _) = run(7, 0, 0.5, 0);
    assert_eq!(var(&vars, "q"), Value::Int(0));
    assert_eq!(var(&vars, "r"), Value::Int(0));
    let (vars, _) = run(i32::MIN as i128, -1, 0.5, 0);
    assert_eq!(var(&vars, "q"), Value::Int(0), "MIN / -1");
    assert_eq!(var(&vars, "r"), Value::Int(0), "MIN % -1");
    let (vars, _) = run(-7, 2, 0.5, 0);
    assert_eq!(var(&vars, "q"), Value::Int(-3));
    assert_eq!(
        var(&vars, "r"),
        Value::Int(-1),
        "the sign of the left operand"
    );
}

#[test]
fn float_to_int_saturates_and_nan_gives_zero() {
    let (vars, _) = run(0, 1, 1e10, 0);
    assert_eq!(var(&vars, "n"), Value::Int(255));
    assert_eq!(var(&vars, "m"), Value::Int(i32::MAX as i128));
    let (vars, _) = run(0, 1, -1.5, 0);
    assert_eq!(var(&vars, "n"), Value::Int(0));
    assert_eq!(var(&vars, "m"), Value::Int(-1));
    let (vars, _) = run(0, 1, f64::NAN, 0);
    assert_eq!(var(&vars, "n"), Value::Int(0));
    assert_eq!(var(&vars, "m"), Value::Int(0));
}

#[test]
fn builtins_wrap_propagate_nan_and_round_half_away() {
    let (vars, _) = run(0, 1, -2.5, i8::MIN as i128);
    assert_eq!(
        var(&vars, "wrapped"),
        Value::Int(-128),
        "abs(i8::MIN) wraps"
    );
    assert_eq!(var(&vars, "rounded"), Value::Float(-3.0));
    assert_eq!(var(&vars, "low"), Value::Float(-2.5));
    assert_eq!(var(&vars, "clamped"), Value::Int(5), "lo > hi gives lo");
    let (vars, _) = run(0, 1, f64::NAN, -3);
    assert_eq!(var(&vars, "wrapped"), Value::Int(3));
    assert!(
        matches!(var(&vars, "low"), Value::Float(f) if f.is_nan()),
        "min(NaN, 1.0)"
    );
}

#[test]
fn nan_is_neither_below_nor_at_or_above() {
    assert_eq!(run(0, 1, 0.5, 0).1, "E1");
    assert_eq!(run(0, 1, 1.0, 0).1, "E2");
    assert_eq!(run(0, 1, f64::NAN, 0).1, "E3");
}

/// `x << s` and `x >> s` as `arith::bitwise` computes them for type `$ty`,
/// against Rust's `checked_shl`/`checked_shr` on `x`'s own type (0 where
/// Rust has no result).
macro_rules! shifts_as_rust {
    ($x:expr, $s:expr, $ty:expr) => {{
        let (x, s) = ($x, $s);
        let want_l = u32::try_from(s)
            .ok()
            .and_then(|s| x.checked_shl(s))
            .unwrap_or(0);
        let want_r = u32::try_from(s)
            .ok()
            .and_then(|s| x.checked_shr(s))
            .unwrap_or(0);
        assert_eq!(
            rcs_dsl::arith::bitwise(rcs_dsl::ast::BinOp::Shl, i128::from(x), s, $ty),
            i128::from(want_l),
            "{x} << {s}"
        );
        assert_eq!(
            rcs_dsl::arith::bitwise(rcs_dsl::ast::BinOp::Shr, i128::from(x), s, $ty),
            i128::from(want_r),
            "{x} >> {s}"
        );
    }};
}

/// Bitwise operators and shifts (LANGUAGE.md §8), against Rust's own on
/// the same types: `&`, `|`, `^`, `!` wrap to the type; a shift by the
/// width or more, or by a negative amount, is 0; `>>` of a signed value is
/// arithmetic.
#[test]
fn bitwise_and_shifts_follow_rust_and_never_panic() {
    use rcs_dsl::arith::bitwise;
    use rcs_dsl::ast::BinOp;
    use rcs_dsl::ir::IntTy;
    for x in [0u16, 1, 0x00FF, 0x8001, 0xFFFF] {
        for y in [0u16, 3, 0x0F0F, 0xFFFF] {
            let (xi, yi) = (i128::from(x), i128::from(y));
            assert_eq!(
                bitwise(BinOp::BitAnd, xi, yi, IntTy::U16),
                i128::from(x & y)
            );
            assert_eq!(bitwise(BinOp::BitOr, xi, yi, IntTy::U16), i128::from(x | y));
            assert_eq!(
                bitwise(BinOp::BitXor, xi, yi, IntTy::U16),
                i128::from(x ^ y)
            );
        }
        for s in [-1i128, 0, 1, 7, 15, 16, 17, 200] {
            shifts_as_rust!(x, s, IntTy::U16);
        }
    }
    for x in [i8::MIN, -5, -1, 0, 1, 100, i8::MAX] {
        for s in [-3i128, 0, 1, 6, 7, 8, 9] {
            shifts_as_rust!(x, s, IntTy::I8);
        }
        let not = rcs_dsl::arith::unary(
            rcs_dsl::ast::UnOp::Not,
            Value::Int(i128::from(x)),
            &rcs_dsl::ir::Type::Int(IntTy::I8),
        );
        assert_eq!(not, Value::Int(i128::from(!x)));
    }
    let not = rcs_dsl::arith::unary(
        rcs_dsl::ast::UnOp::Not,
        Value::Int(0x0F),
        &rcs_dsl::ir::Type::Int(IntTy::U16),
    );
    assert_eq!(not, Value::Int(0xFFF0));
}

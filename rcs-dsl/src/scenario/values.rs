//! Scenario values, both ways: a YAML value read as a run-time value of a
//! plan type (buffers deep-merged, arrays given whole, as a prefix or by
//! index with the rest zero), and a run-time value printed as the language
//! writes it (`2147483647`, `Ahead`, `[1.0, 2.0, …]`) for failure reports.
//! Used by [`super::read`] when a scenario is resolved and by
//! [`super::report`] when a step's expectations are compared.

use super::{err, ScenarioError};
use crate::interp::{wrap, zero, Value};
use crate::ir::*;
use serde_json::Value as Json;
use std::collections::BTreeMap;

/// How many elements of an array a report prints before `…`.
const SHOWN_ELEMENTS: usize = 8;

/// A YAML value as a run-time value of type `t` (what is not given is zero).
pub(crate) fn value(
    ir: &Ir,
    line: usize,
    t: &Type,
    v: &Json,
    what: &str,
) -> Result<Value, ScenarioError> {
    let bad = || {
        err(
            line,
            format!(
                "`{what}`: expected {}, found `{v}`",
                crate::type_name(ir, t)
            ),
        )
    };
    Ok(match (t, v) {
        // An error code by its name: a built-in or one the controller declares.
        (Type::ErrorCode(c), Json::String(name)) => {
            let code = if name == "none" {
                Some(rcs_runtime::ErrorCode::NONE)
            } else {
                crate::error_codes::code_of(ir.controller(*c), name)
            };
            Value::Int(i128::from(code.ok_or_else(bad)?.0))
        }
        (Type::Bool, Json::Bool(b)) => Value::Bool(*b),
        // YAML 1.2's other spellings (the reader takes only `true`/`false`).
        (Type::Bool, Json::String(s)) if matches!(s.as_str(), "True" | "TRUE") => Value::Bool(true),
        (Type::Bool, Json::String(s)) if matches!(s.as_str(), "False" | "FALSE") => {
            Value::Bool(false)
        }
        (Type::Int(it), Json::Number(n)) => {
            let i = n
                .as_i64()
                .map(i128::from)
                .or_else(|| n.as_u64().map(i128::from))
                .ok_or_else(bad)?;
            let (lo, hi) = it.range();
            if i < lo || i > hi {
                return Err(bad());
            }
            Value::Int(wrap(i, *it))
        }
        (Type::Float(ft), Json::Number(n)) => {
            let f = n.as_f64().ok_or_else(bad)?;
            Value::Float(if *ft == FloatTy::F32 {
                f as f32 as f64
            } else {
                f
            })
        }
        (Type::Enum(e), Json::String(_) | Json::Bool(_)) => {
            // A variant called `true` or `false` arrives as a boolean.
            let name = match v {
                Json::String(s) => s.clone(),
                other => other.to_string(),
            };
            Value::Enum(
                ir.enums[e.index()]
                    .variants
                    .iter()
                    .position(|x| x.name == name)
                    .ok_or_else(bad)? as u32,
            )
        }
        (Type::Buffer(_), Json::Object(_))
        | (Type::Array(..), Json::Object(_) | Json::Array(_)) => {
            merge(ir, line, &zero(ir, t), t, v, what)?
        }
        _ => return Err(bad()),
    })
}

/// Merge a YAML value into `base`: a buffer's fields not named keep
/// theirs, as do an array's elements not indexed by a `{ N: value }`
/// mapping; a list is the array's first elements, the rest zero.
pub(crate) fn merge(
    ir: &Ir,
    line: usize,
    base: &Value,
    t: &Type,
    v: &Json,
    what: &str,
) -> Result<Value, ScenarioError> {
    match (t, base, v) {
        (Type::Buffer(b), Value::Buffer(fields), Json::Object(m)) => {
            let bt = &ir.buffer_types[b.index()];
            let mut out = fields.clone();
            for (k, x) in m {
                let fi = bt.fields.iter().position(|f| f.name == *k).ok_or_else(|| {
                    err(
                        line,
                        format!("buffer type `{}` has no field `{k}`", bt.name),
                    )
                })?;
                out[fi] = merge(ir, line, &fields[fi], &bt.fields[fi].ty, x, k)?;
            }
            Ok(Value::Buffer(out))
        }
        (Type::Array(elem, n), Value::Array(_), Json::Array(items)) => {
            let n = *n as usize;
            if items.len() > n {
                return Err(err(
                    line,
                    format!(
                        "`{what}`: {} elements given, but the array holds {n} (a shorter list is its first elements, the rest zero)",
                        items.len()
                    ),
                ));
            }
            let z = zero(ir, elem);
            let mut out = vec![z.clone(); n];
            for (i, x) in items.iter().enumerate() {
                out[i] = merge(ir, line, &z, elem, x, &format!("{what}[{i}]"))?;
            }
            Ok(Value::Array(out))
        }
        (Type::Array(elem, n), Value::Array(elems), Json::Object(m)) => {
            let mut out = elems.clone();
            for (k, x) in m {
                let i = k
                    .parse::<usize>()
                    .ok()
                    .filter(|i| *i < *n as usize && *i < out.len())
                    .ok_or_else(|| {
                        err(
                            line,
                            format!(
                                "`{what}`: `{k}` is not an index of this array (0 to {})",
                                n.saturating_sub(1)
                            ),
                        )
                    })?;
                out[i] = merge(ir, line, &out[i], elem, x, &format!("{what}[{i}]"))?;
            }
            Ok(Value::Array(out))
        }
        _ => value(ir, line, t, v, what),
    }
}

/// Equal, floats within 1e-9.
pub(super) fn float_eq(a: &Value, b: &Value) -> bool {
    match (a, b) {
        (Value::Float(x), Value::Float(y)) => (x - y).abs() <= 1e-9,
        (Value::Buffer(xs), Value::Buffer(ys)) | (Value::Array(xs), Value::Array(ys)) => {
            xs.len() == ys.len() && xs.iter().zip(ys).all(|(x, y)| float_eq(x, y))
        }
        _ => a == b,
    }
}

/// `v` of type `t` as the language writes it: `2147483647`, `1.5`,
/// `Ahead`, `{ direction: Ahead, speed: 0.0 }`, `[1.0, 2.0, …]`.
pub(super) fn show(ir: &Ir, t: &Type, v: &Value) -> String {
    match (t, v) {
        (Type::ErrorCode(c), Value::Int(n)) => crate::error_codes::name_of(
            ir.controller(*c),
            rcs_runtime::ErrorCode(u16::try_from(*n).unwrap_or(u16::MAX)),
        ),
        (_, Value::Bool(b)) => b.to_string(),
        (_, Value::Int(i)) => i.to_string(),
        (_, Value::Float(f)) => format!("{f:?}"),
        (Type::Enum(e), Value::Enum(i)) => ir.enums[e.index()]
            .variants
            .get(*i as usize)
            .map_or_else(|| format!("variant {i}"), |x| x.name.clone()),
        (Type::Buffer(b), Value::Buffer(fields)) => {
            let bt = &ir.buffer_types[b.index()];
            let parts: Vec<String> = bt
                .fields
                .iter()
                .zip(fields)
                .map(|(f, x)| format!("{}: {}", f.name, show(ir, &f.ty, x)))
                .collect();
            format!("{{ {} }}", parts.join(", "))
        }
        (Type::Array(elem, _), Value::Array(xs)) => {
            let mut parts: Vec<String> = xs
                .iter()
                .take(SHOWN_ELEMENTS)
                .map(|x| show(ir, elem, x))
                .collect();
            if xs.len() > SHOWN_ELEMENTS {
                parts.push("…".to_string());
            }
            format!("[{}]", parts.join(", "))
        }
        (_, Value::Enum(i)) => format!("variant {i}"),
        (_, Value::Status(s)) => s.to_string(),
        (_, Value::Unit) => "()".to_string(),
        (_, Value::Buffer(_) | Value::Array(_)) => "?".to_string(),
    }
}

/// Where two values of type `t` first differ, when that is inside an
/// array long enough to be cut in [`show`]: ` (first difference at [i]: a against b)`.
pub(super) fn first_difference(ir: &Ir, t: &Type, want: &Value, got: &Value) -> String {
    if let (Type::Array(elem, _), Value::Array(ws), Value::Array(gs)) = (t, want, got) {
        if ws.len() > SHOWN_ELEMENTS {
            if let Some(i) = ws.iter().zip(gs).position(|(w, g)| !float_eq(w, g)) {
                return format!(
                    " (first difference at [{i}]: expected {}, got {})",
                    show(ir, elem, &ws[i]),
                    show(ir, elem, &gs[i])
                );
            }
        }
    }
    String::new()
}

fn object<'j>(
    line: usize,
    v: Option<&'j Json>,
    what: &str,
) -> Result<Vec<(&'j String, &'j Json)>, ScenarioError> {
    match v {
        None | Some(Json::Null) => Ok(Vec::new()),
        Some(Json::Object(m)) => Ok(m.iter().collect()),
        Some(_) => Err(err(
            line,
            format!("`{what}` is a mapping of names to values"),
        )),
    }
}

/// `VERB` or `{ VERB: { param: value } }` for controller `c`; `shape`
/// says what was expected when the value has neither form.
pub(super) fn verb_call(
    ir: &Ir,
    c: &Controller,
    line: usize,
    v: &Json,
    shape: impl FnOnce() -> String,
) -> Result<(CommandId, Vec<Value>), ScenarioError> {
    let (verb, args) = match v {
        Json::String(s) => (s.as_str(), None),
        Json::Object(m) if m.len() == 1 => {
            let Some((k, a)) = m.iter().next() else {
                return Err(err(line, shape()));
            };
            (k.as_str(), Some(a))
        }
        // `true` and `false` are the only booleans a scenario reads.
        Json::Bool(b) if c.commands.iter().any(|k| k.name == b.to_string()) => {
            return verb_args(ir, c, line, &b.to_string(), None)
        }
        _ => return Err(err(line, shape())),
    };
    verb_args(ir, c, line, verb, args)
}

fn verb_args(
    ir: &Ir,
    c: &Controller,
    line: usize,
    verb: &str,
    args: Option<&Json>,
) -> Result<(CommandId, Vec<Value>), ScenarioError> {
    let ci = c
        .commands
        .iter()
        .position(|k| k.name == verb)
        .ok_or_else(|| err(line, format!("`{}` has no command `{verb}`", c.name)))?;
    let cmd = &c.commands[ci];
    let given: BTreeMap<&String, &Json> = object(line, args, "parameters")?.into_iter().collect();
    for k in given.keys() {
        if !cmd.params.iter().any(|p| p.name == **k) {
            return Err(err(
                line,
                format!("command `{verb}` of `{}` has no parameter `{k}`", c.name),
            ));
        }
    }
    let mut vals = Vec::new();
    for p in &cmd.params {
        let v = given.get(&p.name).ok_or_else(|| {
            err(
                line,
                format!("command `{verb}` needs parameter `{}`", p.name),
            )
        })?;
        vals.push(value(ir, line, &p.ty, v, &p.name)?);
    }
    Ok((CommandId(ci as u32), vals))
}

//! The IR as meaning, for the tools that rewrite `.rcs` text and must
//! prove they did not change a plan (the formatter's golden test,
//! `--renumber`'s self-check): the IR as `rcsc ir --format json` gives it,
//! without the places in the text, and where two such values first differ.

use crate::ir::Ir;
use serde_json::Value;

/// `ir` as JSON without any span, row line number or file list: what it
/// means, not where it is written.
pub fn without_places(ir: &Ir) -> Value {
    let mut value = serde_json::to_value(ir).unwrap_or(Value::Null);
    if let Value::Object(map) = &mut value {
        // File names depend on how the set was loaded, not on its plans.
        map.remove("files");
    }
    strip_spans(&mut value);
    value
}

fn strip_spans(v: &mut Value) {
    match v {
        // A span, whatever its key: a place in the text, not meaning.
        Value::Object(map)
            if map.len() == 3
                && ["file", "start", "end"]
                    .iter()
                    .all(|k| map.contains_key(*k)) =>
        {
            *v = Value::Null;
        }
        Value::Object(map) => {
            // `line`: a row's line in its file, for people.
            map.retain(|k, _| k != "line");
            map.values_mut().for_each(strip_spans);
        }
        Value::Array(items) => items.iter_mut().for_each(strip_spans),
        _ => {}
    }
}

/// Where two JSON values first differ: a path from the root (`at`) and
/// both values.
pub fn first_difference(a: &Value, b: &Value, at: String) -> String {
    match (a, b) {
        (Value::Object(x), Value::Object(y)) => {
            for (k, v) in x {
                match y.get(k) {
                    Some(w) if v != w => return first_difference(v, w, format!("{at}.{k}")),
                    None => return format!("{at}.{k} missing after"),
                    _ => {}
                }
            }
            format!(
                "{at}: keys {:?} added",
                y.keys().filter(|k| !x.contains_key(*k)).collect::<Vec<_>>()
            )
        }
        (Value::Array(x), Value::Array(y)) if x.len() == y.len() => x
            .iter()
            .zip(y)
            .enumerate()
            .find(|(_, (v, w))| v != w)
            .map(|(i, (v, w))| first_difference(v, w, format!("{at}[{i}]")))
            .unwrap_or_default(),
        _ => format!("{at}: {a} became {b}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn spans_and_lines_go_and_the_first_difference_is_named() {
        let mut a =
            json!({"rows": [{"span": {"file": 0, "start": 1, "end": 2}, "line": 3, "to": "S1"}]});
        strip_spans(&mut a);
        assert_eq!(a, json!({"rows": [{"span": null, "to": "S1"}]}));
        let b = json!({"rows": [{"span": null, "to": "S2"}]});
        assert_eq!(
            first_difference(&a, &b, String::new()),
            ".rows[0].to: \"S1\" became \"S2\""
        );
    }
}

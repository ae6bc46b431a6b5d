//! The generated plan set the `check` benchmark measures: `n` controllers
//! × 10 plans, spread over files of ten controllers each, in a tree with
//! five subordinates per supervisor. Shared by `benches/check.rs` and
//! `examples/check_set.rs` (one `check` for profilers such as callgrind).

use std::fmt::Write;

const PLANS: usize = 10;
const FANOUT: usize = 5;

/// One controller of the generated hierarchy, with its ten plans.
fn controller(i: usize, n: usize, out: &mut String) {
    let children: Vec<usize> = (1..=FANOUT)
        .map(|k| i * FANOUT + k)
        .filter(|c| *c < n)
        .collect();
    let depth = {
        let (mut d, mut j) = (0, i);
        while j > 0 {
            j = (j - 1) / FANOUT;
            d += 1;
        }
        d
    };
    let _ = writeln!(
        out,
        "/// Generated controller {i}.\ncontroller C{i} \"Controller {i}\" {{"
    );
    let _ = writeln!(out, "    level {}", 30 - depth);
    if !children.is_empty() {
        let list: Vec<String> = children.iter().map(|c| format!("C{c}")).collect();
        let _ = writeln!(out, "    subordinates {}", list.join(", "));
    }
    let _ = writeln!(out, "    reads s{i}: Sensors\n    writes d{i}: Drive");
    for k in 0..PLANS {
        let _ = writeln!(out, "    command OP{k}(goal: f64)");
    }
    let _ = writeln!(
        out,
        "    status AT_GOAL\n    error TIMEOUT, FAULT\n    var acc: f64 = 0.0\n    var count: u32 = 0\n    hook estimate(goal: f64) -> f64"
    );
    for k in 0..PLANS {
        let send = children
            .first()
            .map(|c| format!("; C{c} <- OP{k}(goal: acc)"))
            .unwrap_or_default();
        let child_done = children
            .first()
            .map(|c| format!("C{c}.done && "))
            .unwrap_or_default();
        let _ = write!(
            out,
            "    plan OP{k} {{
        E0: *0 when new_command -> S1 {{ acc = estimate(cmd.goal); d{i}.set = acc; d{i}.on = true{send} }}
        E1: *1 when s{i}.mode == Fault -> Error(FAULT)
        E2: S1 when {child_done}s{i}.x > cmd.goal - 0.5 && s{i}.x < cmd.goal + 0.5 -> S2 {{ report AT_GOAL; count += 1 }}
        E3: S1 when s{i}.x < cmd.goal - 0.5 && s{i}.ok -> S1 {{ acc += 1.0; d{i}.set = acc }}
        E4: S1 when state_cycles > 200 -> Error(TIMEOUT)
        E5: S2 when count > 3 || plan_cycles > 1000 -> Done {{ d{i}.on = false }}
        *6 otherwise -> same
    }}
"
        );
    }
    out.push_str("}\n\n");
}

/// A plan set of `n` controllers as (path, text) pairs.
pub fn plan_set(n: usize) -> Vec<(String, String)> {
    let mut files = vec![(
        "types.rcs".to_string(),
        "enum Mode { Idle, Run, Fault }\nbuffer Sensors { x: f64, n: i32, ok: bool, mode: Mode }\nbuffer Drive { set: f64, on: bool }\n"
            .to_string(),
    )];
    for chunk in (0..n).collect::<Vec<_>>().chunks(10) {
        let mut text = String::new();
        for &i in chunk {
            controller(i, n, &mut text);
        }
        files.push((format!("c{:05}.rcs", chunk[0]), text));
    }
    files
}

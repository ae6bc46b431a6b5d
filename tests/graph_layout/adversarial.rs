//! Plans written to be hard to draw, for the layout check: what a
//! reviewer's real plans do a little of, done a lot. Each is one `.rcs`
//! file with one controller; they need not pass the analysis (the graphs of
//! a set whose checks fail are drawn from its IR all the same).

use std::fmt::Write;

/// A controller `A` with variables `v0..v9`, commands `GO` and `STOP`,
/// and the given plan body for `GO`.
fn controller(body: &str) -> String {
    let mut out =
        String::from("controller A {\n    command GO\n    command STOP\n    error FAULT\n");
    for i in 0..10 {
        let _ = writeln!(out, "    var v{i}: u16 = 0");
    }
    let _ = write!(
        out,
        "    plan GO {{\n{body}    }}\n    plan STOP {{\n        E0: *0 when new_command -> Done\n    }}\n}}\n"
    );
    out
}

/// A condition of `n` comparisons, each on its own variable.
fn long_condition(seed: usize, n: usize) -> String {
    (0..n)
        .map(|k| {
            format!(
                "v{} + {} > v{} * {}",
                (seed + k) % 10,
                100 + k,
                (seed + k + 3) % 10,
                k + 2
            )
        })
        .collect::<Vec<_>>()
        .join(" && ")
}

/// A job list of `n` assignments.
fn long_jobs(seed: usize, n: usize) -> String {
    (0..n)
        .map(|k| {
            format!(
                "v{} = v{} + {}",
                (seed + k) % 10,
                (seed + k + 1) % 10,
                1000 + k
            )
        })
        .collect::<Vec<_>>()
        .join("; ")
}

/// (name, source) of every adversarial plan set.
pub fn plans() -> Vec<(&'static str, String)> {
    let mut out = Vec::new();

    // A chain of six states whose rows have very long conditions and jobs.
    let mut body = format!(
        "        E0: *0 when new_command && {} -> S1 {{ {} }}\n",
        long_condition(0, 6),
        long_jobs(0, 5)
    );
    for s in 1..6 {
        let _ = writeln!(
            body,
            "        S{s} when {} -> S{} {{ {} }}",
            long_condition(s, 5 + s % 3),
            s + 1,
            long_jobs(s, 4)
        );
    }
    body.push_str("        S6 when v1 > 3 -> Done\n");
    out.push(("long_conditions", controller(&body)));

    // Five states, each with four self-loops and a way on.
    let mut body = String::from("        E0: *0 when new_command -> S1\n");
    for s in 1..=5 {
        for k in 0..4 {
            let _ = writeln!(
                body,
                "        S{s} when v{k} == {} && {} -> same {{ {} }}",
                s * 10 + k,
                long_condition(s + k, 2),
                long_jobs(k, 2)
            );
        }
        let next = if s == 5 {
            "Done".to_string()
        } else {
            format!("S{}", s + 1)
        };
        let _ = writeln!(body, "        S{s} when v9 == {s} -> {next}");
    }
    out.push(("many_self_loops", controller(&body)));

    // Twelve don't-care rows beside a loop-heavy state.
    let mut body = String::new();
    for k in 0..12 {
        let to = ["S1", "S2", "S3", "Error(FAULT)", "Done"][k % 5];
        let _ = writeln!(
            body,
            "        *{k} when new_command && v{} == {} -> {to} {{ v{} = {} }}",
            k % 10,
            k + 1,
            (k + 1) % 10,
            k
        );
    }
    for (s, next) in [(1, 2), (2, 3), (3, 1)] {
        for k in 0..3 {
            let _ = writeln!(
                body,
                "        S{s} when v{k} > {} -> same {{ v{} = 1 }}",
                s + k,
                k + 3
            );
        }
        let _ = writeln!(body, "        S{s} when v9 == {s} -> S{next}");
    }
    body.push_str("        S3 when v8 == 9 -> Done\n");
    out.push(("many_dont_cares", controller(&body)));

    // State sets and `except` rows, with an `otherwise` that leaves.
    let mut body = String::from("        E0: *0 when new_command -> S1\n");
    for s in 1..=6 {
        let next = if s == 6 {
            "Done".to_string()
        } else {
            format!("S{}", s + 1)
        };
        let _ = writeln!(body, "        S{s} when v{s} == 1 -> {next} {{ v0 = {s} }}");
    }
    body.push_str("        S1 | S2 | S3 when v7 > 5 && v8 < 2 -> S6 { v9 = 9 }\n");
    body.push_str("        S4 | S5 when v7 > 6 -> S1\n");
    body.push_str("        * except S1 | S2 when v0 == 99 -> Error(FAULT) { v1 = 0; v2 = 0 }\n");
    body.push_str("        * except S6 when v3 == 98 -> same { v4 = 1 }\n");
    body.push_str("        otherwise -> Error(FAULT)\n");
    out.push(("state_sets", controller(&body)));

    // A long chain: wider than a page if drawn left to right.
    let mut body = String::from("        E0: *0 when new_command -> S1\n");
    for s in 1..=24 {
        let next = if s == 24 {
            "Done".to_string()
        } else {
            format!("S{}", s + 1)
        };
        let _ = writeln!(
            body,
            "        S{s} when v{} >= {s} -> {next} {{ v{} = {s} }}",
            s % 10,
            (s + 1) % 10
        );
        if s % 4 == 0 {
            let _ = writeln!(body, "        S{s} when v0 == 0 -> S{}", s / 2);
        }
    }
    out.push(("long_chain", controller(&body)));
    out
}

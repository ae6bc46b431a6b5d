//! The layout, case by case: tables, wrapping, comments, blank lines,
//! hostile input.

use super::*;

fn fmt(text: &str) -> String {
    format(text, &FmtOptions::default()).unwrap()
}

fn fmt_width(text: &str, max_width: usize) -> String {
    format(text, &FmtOptions { max_width }).unwrap()
}

#[test]
fn rows_are_a_table() {
    // Targets are padded only in rows with jobs on the line.
    let text = "controller A {\ncommand GO\n  subordinates B\nplan GO {\nE0: *0 when new_command -> S1 { B <- RUN }\nE1: S1 when B.done -> Done\nE2: S1 when B.error -> Error\n}\n}\n";
    assert_eq!(
        fmt(text),
        "controller A {\n    command GO\n    subordinates B\n    plan GO {\n        \
         E0: *0 when new_command -> S1 { B <- RUN }\n        \
         E1: S1 when B.done      -> Done\n        \
         E2: S1 when B.error     -> Error\n    }\n}\n"
    );
}

#[test]
fn a_long_condition_is_broken_before_its_loosest_operator() {
    let text = "controller A { command GO plan GO {\n*0 when new_command && alpha_value > 1 && beta_value > 2 && gamma_value > 3 -> Done { x = 1 }\n} }";
    let out = fmt_width(text, 60);
    assert_eq!(
        out,
        "controller A {\n    command GO\n    plan GO {\n        \
         *0 when new_command && alpha_value > 1\n                \
         && beta_value > 2 && gamma_value > 3\n                -> Done {\n            x = 1\n        }\n    }\n}\n"
    );
    assert!(out.lines().all(|l| l.len() <= 60), "{out}");
}

#[test]
fn comments_stay_where_they_were() {
    let text = "// head\n\n/// doc\ncontroller A { // after the brace\n  command GO   // why\n\n\n  /* block */ plan GO {\n  // before the row\n  *0 when new_command /* inside */ -> Done\n  }\n}\n// tail\n";
    let out = fmt(text);
    assert_eq!(
        out,
        // `// why` keeps its column (15) as the code ends before it.
        "// head\n\n/// doc\ncontroller A { // after the brace\n    command GO // why\n\n    \
         /* block */\n    plan GO {\n        // before the row\n        \
         *0 when new_command /* inside */ -> Done\n    }\n}\n\n// tail\n"
    );
    assert_eq!(fmt(&out), out);
}

#[test]
fn jobs_separators_and_trailing_commas_are_normalised() {
    let text = "enum E { A, B, }\ncontroller A {\n    command GO\n    var x: u8 = 0\n    plan GO {\n        *0 when new_command -> Done { x = 1;; x += 2 }\n        * when x > 1 -> Done {\n            x = 1; x = 2;\n        }\n    }\n}\n";
    assert_eq!(
        fmt(text),
        "enum E { A, B }\n\ncontroller A {\n    command GO\n    var x: u8 = 0\n    plan GO {\n        \
         *0 when new_command -> Done { x = 1; x += 2 }\n        \
         *  when x > 1       -> Done {\n            x = 1\n            x = 2\n        }\n    }\n}\n"
    );
}

#[test]
fn one_line_items_keep_their_grouping_and_blocks_get_a_blank_line() {
    let text = "const A: u8 = 1\nconst B: u8 = 2\nbuffer X {\n a: u8,\n}\nconst C: u8 = 3\n\n\n\nconst D: u8 = 4";
    assert_eq!(
        fmt(text),
        "const A: u8 = 1\nconst B: u8 = 2\n\nbuffer X {\n    a: u8,\n}\n\nconst C: u8 = 3\n\nconst D: u8 = 4\n"
    );
}

#[test]
fn spacing_around_operators_and_inside_brackets() {
    let text = "controller A{command GO(x:f64,y:[u8;2])\nvar v:u8=0\nplan GO{*0 when new_command&&-cmd.x<( 1.0 )*2.0&&!(v==1)&&cmd.y[ 0 ]as f64>0.5->Done{v=min( v,2 )}}}";
    assert_eq!(
        fmt(text),
        "controller A {\n    command GO(x: f64, y: [u8; 2])\n    var v: u8 = 0\n    plan GO {\n        \
         *0 when new_command && -cmd.x < (1.0) * 2.0 && !(v == 1) && cmd.y[0] as f64 > 0.5 -> Done {\n            v = min(v, 2)\n        }\n    }\n}\n"
    );
}

#[test]
fn a_file_that_does_not_parse_is_refused() {
    assert!(matches!(
        format("controller A {", &FmtOptions::default()),
        Err(FmtError::Syntax(_))
    ));
}

#[test]
fn hostile_input_never_panics_and_round_trips() {
    let deep = "(".repeat(10_000);
    let nested = format!(
        "controller A {{ command GO plan GO {{ *0 when {}x{} -> Done }} }}",
        "(".repeat(60),
        ")".repeat(60)
    );
    for text in [
        deep.as_str(),
        nested.as_str(),
        "\u{FEFF}",
        "/* never closed",
        "\"never closed",
        "controller A { command GO plan GO { *0 when new_command -> Done } } \u{0}",
        "\r\r\r\n\t\x0b\x0c",
        "controller \u{1F600} {}",
        "///",
        "//",
    ] {
        assert_eq!(parse(text).root().to_string(), text);
        if let Ok(out) = format(text, &FmtOptions::default()) {
            assert_eq!(format(&out, &FmtOptions::default()).unwrap(), out);
        }
    }
}

#[test]
fn a_long_accept_condition_is_broken_like_a_rows() {
    let text = "controller A {\n    status s: u8 = 0\n    command STOP accept when s != 1 && s != 2 && s != 3 && s != 4\n    plan STOP { *0 when new_command -> Done }\n}\n";
    let out = fmt_width(text, 50);
    assert!(
        out.contains(
            "    command STOP accept when s != 1 && s != 2\n            && s != 3 && s != 4\n"
        ),
        "{out}"
    );
    assert_eq!(fmt_width(&out, 50), out);
}

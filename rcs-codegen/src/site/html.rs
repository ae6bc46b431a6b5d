//! Small HTML pieces shared by the pages: escaping, the page shell with
//! its header and search box, doc comments as paragraphs, findings.

use crate::GENERATED;
use rcs_dsl::Diagnostic;
use std::fmt::Write;

/// Escape text for HTML content and (double-quoted) attribute values.
pub(super) fn esc(s: &str) -> String {
    crate::dot::markup(s, "\n")
}

/// A whole page: `root` leads back to the site's root (`""` or `../`).
pub(super) fn page(title: &str, root: &str, body: &str) -> String {
    let title = esc(title);
    format!(
        "<!-- {GENERATED}. Do not edit. -->\n<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n\
         <meta charset=\"utf-8\">\n<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
         <title>{title}</title>\n<link rel=\"stylesheet\" href=\"{root}site.css\">\n\
         <script src=\"{root}site.js\" defer></script>\n\
         </head>\n<body data-root=\"{root}\">\n<header>\n<a class=\"home\" href=\"{root}index.html\">rcsc doc</a>\n\
         <input id=\"search\" type=\"search\" placeholder=\"Search controllers, verbs, buffers, states\" autocomplete=\"off\" aria-label=\"Search\">\n\
         <ul id=\"results\" hidden></ul>\n</header>\n<main>\n<h1>{title}</h1>\n{body}</main>\n</body>\n</html>\n"
    )
}

/// Doc comments as one paragraph (nothing when there are none).
pub(super) fn docs(lines: &[String]) -> String {
    if lines.is_empty() {
        return String::new();
    }
    format!("<p class=\"docs\">{}</p>\n", esc(&lines.join("\n")))
}

/// A finding as the site shows it: severity, code, message, witness,
/// notes and help.
pub(super) fn finding(d: &Diagnostic) -> String {
    let mut out = format!(
        "<div class=\"finding {}\"><b>{}[{}]</b>: {}",
        d.severity.as_str(),
        d.severity.as_str(),
        d.code.name(),
        esc(&d.message)
    );
    if let Some(w) = &d.witness {
        let inputs: Vec<String> = w
            .inputs
            .iter()
            .map(|i| format!("{} = {}", i.name, i.value))
            .collect();
        let _ = write!(
            out,
            "<div class=\"witness\">witness: in state <code>{}</code>{}{}</div>",
            esc(&w.state),
            if inputs.is_empty() { "" } else { " with " },
            esc(&inputs.join(", "))
        );
    }
    for n in &d.notes {
        let _ = write!(out, "<div class=\"note\">note: {}</div>", esc(n));
    }
    if let Some(h) = &d.help {
        let _ = write!(out, "<div class=\"note\">help: {}</div>", esc(h));
    }
    out.push_str("</div>\n");
    out
}

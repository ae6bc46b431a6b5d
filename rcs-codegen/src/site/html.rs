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

/// Doc comments, rendered as Markdown (nothing when there are none).
pub(super) fn docs(lines: &[String]) -> String {
    super::markdown::docs_html(lines)
}

/// A finding as the site shows it: severity, code, message, witness,
/// notes and help.
pub(super) fn finding(d: &Diagnostic) -> String {
    use super::markdown::message_html;
    let mut out = format!(
        "<div class=\"finding {}\"><b>{}[{}]</b>: {}",
        d.severity.as_str(),
        d.severity.as_str(),
        d.code.name(),
        message_html(&d.message)
    );
    // The witness once: as its own block, not also as the note that
    // says the same for the terminal.
    let example = d.witness.as_ref().map(|w| w.example_note());
    if let Some(w) = &d.witness {
        let inputs: Vec<String> = w
            .inputs
            .iter()
            .map(|i| format!("<code>{} = {}</code>", esc(&i.name), esc(&i.value)))
            .collect();
        let _ = write!(
            out,
            "<div class=\"witness\">witness: in state <code>{}</code>{}{}{}</div>",
            esc(&w.state),
            if inputs.is_empty() { "" } else { " with " },
            inputs.join(", "),
            if w.run.is_some() {
                " — <code>rcsc check --witnesses DIR</code> writes a scenario that replays it"
            } else {
                ""
            }
        );
    }
    for n in d.notes.iter().filter(|n| Some(*n) != example.as_ref()) {
        let _ = write!(out, "<div class=\"note\">note: {}</div>", message_html(n));
    }
    if let Some(h) = &d.help {
        let _ = write!(out, "<div class=\"note\">help: {}</div>", message_html(h));
    }
    out.push_str("</div>\n");
    out
}

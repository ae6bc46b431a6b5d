//! Text the user wrote, as the site shows it: doc comments are Markdown
//! (pulldown-cmark: inline code, emphasis, links, lists, code blocks), and
//! the messages of findings mark names with backticks, shown as code.
//!
//! Doc comments come from plan files anyone may have written, and the site
//! is opened in a browser: raw HTML in them is shown as text, never passed
//! through, and a link or image may only lead to a relative address, an
//! anchor, `http(s):` or `mailto:` — a `javascript:` or `data:` link is
//! shown as its text. Images become their alt text (the site works
//! offline and draws nothing it did not make).

use super::html::esc;
use pulldown_cmark::{Event, Options, Parser, Tag, TagEnd};

/// Whether a link target is one the site may follow.
fn safe_url(url: &str) -> bool {
    let lower = url.trim().to_ascii_lowercase();
    match lower.split_once(':') {
        // A colon before any `/`, `?` or `#` names a scheme.
        Some((scheme, _)) if !scheme.contains(['/', '?', '#']) => {
            matches!(scheme, "http" | "https" | "mailto")
        }
        _ => true,
    }
}

/// Doc comment lines as HTML (nothing when there are none), in a
/// `<div class="docs">`.
pub(super) fn docs_html(lines: &[String]) -> String {
    if lines.is_empty() {
        return String::new();
    }
    let text = lines.join("\n");
    let mut skipping_link = 0usize;
    let mut events = Vec::new();
    for ev in Parser::new_ext(
        &text,
        Options::ENABLE_STRIKETHROUGH | Options::ENABLE_TABLES,
    ) {
        match ev {
            // Raw HTML is shown, not obeyed.
            Event::Html(h) | Event::InlineHtml(h) => events.push(Event::Text(h)),
            Event::Start(Tag::Link {
                link_type,
                dest_url,
                title,
                id,
            }) => {
                if safe_url(&dest_url) {
                    events.push(Event::Start(Tag::Link {
                        link_type,
                        dest_url,
                        title,
                        id,
                    }));
                } else {
                    skipping_link += 1;
                }
            }
            Event::End(TagEnd::Link) => {
                if skipping_link > 0 {
                    skipping_link -= 1;
                } else {
                    events.push(Event::End(TagEnd::Link));
                }
            }
            // An image: its alt text (the events inside the tag) alone.
            Event::Start(Tag::Image { .. }) | Event::End(TagEnd::Image) => {}
            other => events.push(other),
        }
    }
    let mut out = String::from("<div class=\"docs\">");
    pulldown_cmark::html::push_html(&mut out, events.into_iter());
    out.push_str("</div>\n");
    out
}

/// A message with `code` spans (a finding's message, note or help) as HTML:
/// escaped, each backticked span in `<code>`. An unpaired backtick stays
/// as it is.
pub(super) fn message_html(text: &str) -> String {
    let parts: Vec<&str> = text.split('`').collect();
    if parts.len().is_multiple_of(2) {
        // An odd number of backticks: not code spans.
        return esc(text);
    }
    let mut out = String::new();
    for (k, part) in parts.iter().enumerate() {
        if k % 2 == 1 {
            out.push_str("<code>");
            out.push_str(&esc(part));
            out.push_str("</code>");
        } else {
            out.push_str(&esc(part));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn doc(s: &str) -> String {
        docs_html(&s.lines().map(str::to_string).collect::<Vec<_>>())
    }

    #[test]
    fn inline_code_emphasis_and_links_are_rendered() {
        let h = doc("Ends in `Error` when *TB* fails; see [the paper](https://example.org/rcs).");
        assert!(h.contains("<code>Error</code>"), "{h}");
        assert!(h.contains("<em>TB</em>"), "{h}");
        assert!(
            h.contains("<a href=\"https://example.org/rcs\">the paper</a>"),
            "{h}"
        );
    }

    #[test]
    fn raw_html_and_script_links_are_shown_as_text() {
        let h = doc("<script>alert(1)</script> and <b onclick=\"x()\">bold</b>\n[click](javascript:alert(1)) [d](DATA:text/html,x)");
        assert!(!h.contains("<script"), "{h}");
        assert!(!h.contains("<b onclick"), "{h}");
        assert!(h.contains("&lt;script&gt;"), "{h}");
        assert!(!h.to_ascii_lowercase().contains("href=\"javascript"), "{h}");
        assert!(!h.to_ascii_lowercase().contains("href=\"data"), "{h}");
        assert!(h.contains("click"), "{h}");
    }

    #[test]
    fn images_become_their_alt_text() {
        let h = doc("![the graph](http://example.org/x.png)");
        assert!(!h.contains("<img"), "{h}");
        assert!(h.contains("the graph"), "{h}");
    }

    #[test]
    fn relative_links_and_anchors_are_kept() {
        let h = doc("[PR](PR.html) and [row](#row-E2)");
        assert!(h.contains("href=\"PR.html\""), "{h}");
        assert!(h.contains("href=\"#row-E2\""), "{h}");
    }

    #[test]
    fn messages_mark_backticked_names_as_code() {
        assert_eq!(
            message_html("plan `DRAIN` can hang in `S0` <b>"),
            "plan <code>DRAIN</code> can hang in <code>S0</code> &lt;b&gt;"
        );
        assert_eq!(message_html("a ` alone"), "a ` alone");
    }
}

//! Links (and run weights) put into DOT before Graphviz renders it, and
//! the SVG made fit to sit inside a page. Keyed only on the `id`s that
//! [`crate::dot`] gives nodes and edges: each `id="…"` gets a `URL` beside
//! it, which Graphviz renders as an SVG link around the node or edge.

use std::collections::BTreeMap;

/// Every `id="…"` attribute of the DOT text with `prefix`, and the byte
/// just after its closing quote. An `id` inside a quoted string is escaped
/// (`\"`), so it cannot match.
fn ids<'a>(dot: &'a str, prefix: &str) -> Vec<(&'a str, usize)> {
    let needle = format!("id=\"{prefix}");
    let mut out = Vec::new();
    let mut from = 0;
    while let Some(at) = dot[from..].find(&needle) {
        let start = from + at;
        let before = dot[..start].chars().next_back();
        let value_start = start + 4;
        let Some(len) = dot[value_start..].find('"') else {
            break;
        };
        let end = value_start + len + 1;
        if matches!(before, Some('[' | ' ' | ',')) {
            out.push((&dot[value_start..end - 1], end));
        }
        from = end;
    }
    out
}

/// Insert after each chosen id the attributes `extra` gives for it.
fn insert(dot: &str, prefix: &str, extra: impl Fn(&str) -> Option<String>) -> String {
    let mut out = String::with_capacity(dot.len() + 256);
    let mut last = 0;
    for (id, end) in ids(dot, prefix) {
        if let Some(attrs) = extra(id) {
            out.push_str(&dot[last..end]);
            out.push_str(&attrs);
            last = end;
        }
    }
    out.push_str(&dot[last..]);
    out
}

/// A plan graph whose nodes link to their state (a `*N` node to its row)
/// and whose edges link to their first row; with `weights` (hits per row
/// name), edges drawn heavier the more they fired and never-fired ones
/// classed `never`.
pub(super) fn link_plan(dot: &str, weights: Option<&BTreeMap<String, u64>>) -> String {
    let dot = insert(dot, "node-", |id| {
        let name = id.strip_prefix("node-")?;
        Some(match name.strip_prefix("any-") {
            Some(row) => format!(", URL=\"#row-{row}\""),
            None => format!(", URL=\"#state-{name}\""),
        })
    });
    let max = weights.and_then(|w| w.values().copied().max()).unwrap_or(0);
    insert(&dot, "edge-", |id| {
        let rows: Vec<&str> = id.strip_prefix("edge-")?.split('-').collect();
        let first = rows.first()?;
        let mut attrs = format!(", URL=\"#row-{first}\"");
        if let Some(w) = weights {
            // An edge is as heavy as its busiest row, never more: a shared
            // edge whose other rows never fired is not drawn as if they had
            // (each row's own count is on the edge's label).
            let hits: u64 = rows
                .iter()
                .filter_map(|r| w.get(*r))
                .copied()
                .max()
                .unwrap_or(0);
            if hits == 0 {
                attrs.push_str(", class=\"never\"");
            } else {
                let scale = (((1 + hits) as f64).ln() / ((1 + max.max(1)) as f64).ln()).min(1.0);
                attrs.push_str(&format!(
                    ", class=\"fired\", penwidth={:.2}",
                    1.0 + 4.0 * scale
                ));
            }
        }
        Some(attrs)
    })
}

/// The hierarchy with each controller's node linking to its page, from the
/// site's root.
pub(super) fn link_hierarchy(dot: &str, folder: &str) -> String {
    insert(dot, "ctrl-", |id| {
        let name = id.strip_prefix("ctrl-")?;
        Some(format!(", URL=\"{folder}{name}.html\""))
    })
}

/// Graphviz's SVG document made an element to put inside a page: the XML
/// prologue and doctype dropped.
pub(super) fn inline(svg: &str) -> &str {
    match svg.find("<svg") {
        Some(at) => svg[at..].trim_end(),
        None => "",
    }
}

/// The smallest text a graph may show on a page, in CSS px (issue 29).
pub(super) const MIN_TEXT_PX: f64 = 10.0;

/// How wide, in CSS px, `svg` (Graphviz's, inlined) must be shown so that
/// its smallest text is still [`MIN_TEXT_PX`]: the page shrinks a graph to
/// its column (`max-width: 100%` in `site.css`), and this is the floor it
/// may not go under (`min-width`; past it the graph's box scrolls). Text of
/// `font-size` f user units in a viewBox w units wide, shown W px wide, is
/// f·W/w px high, so W ≥ 10·w/f. `None` without a viewBox or text (the
/// stand-in SVGs of tests).
pub(super) fn min_width_px(svg: &str) -> Option<u32> {
    let tag = &svg[..svg.find('>')?];
    let view_width: f64 = attr(tag, "viewBox")?
        .split_whitespace()
        .nth(2)?
        .parse()
        .ok()?;
    // Graphviz scales its whole drawing in the first group's transform
    // (`scale(1 1)` unless the DOT asks for a size).
    let scale = svg
        .find("transform=\"scale(")
        .and_then(|at| svg[at + 17..].split([' ', ')']).next()?.parse::<f64>().ok())
        .filter(|s| *s > 0.0)
        .unwrap_or(1.0);
    let smallest = svg
        .match_indices("font-size=\"")
        .filter_map(|(at, m)| {
            let rest = &svg[at + m.len()..];
            rest[..rest.find('"')?].parse::<f64>().ok()
        })
        .filter(|f| *f > 0.0)
        .fold(f64::INFINITY, f64::min);
    if !smallest.is_finite() || view_width <= 0.0 {
        return None;
    }
    Some((MIN_TEXT_PX * view_width / (smallest * scale)).ceil() as u32)
}

/// The value of attribute `name` in a start tag's text.
fn attr<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    let needle = format!(" {name}=\"");
    let at = tag
        .find(&needle)
        .or_else(|| tag.find(&format!("\n{name}=\"")))?;
    let rest = &tag[at + needle.len()..];
    Some(&rest[..rest.find('"')?])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ids_get_links_and_quoted_text_is_left_alone() {
        let dot = r#"digraph { "S1" [id="node-S1"]; "*3" [id="node-any-E3", label="x"]; "S1" -> "S1" [id="edge-E2-E4", label=<a>, tooltip="see id=\"edge-E9\""]; }"#;
        let w: BTreeMap<String, u64> = [
            ("E2".to_string(), 3),
            ("E4".to_string(), 1),
            ("E9".to_string(), 0),
        ]
        .into();
        let out = link_plan(dot, Some(&w));
        assert!(
            out.contains(r##"[id="node-S1", URL="#state-S1"]"##),
            "{out}"
        );
        assert!(
            out.contains(r##"[id="node-any-E3", URL="#row-E3", label"##),
            "{out}"
        );
        assert!(
            out.contains(
                r##"[id="edge-E2-E4", URL="#row-E2", class="fired", penwidth=5.00, label"##
            ),
            "{out}"
        );
        assert!(out.contains(r#"tooltip="see id=\"edge-E9\"""#), "{out}");
        let h = link_hierarchy(r#""PR" [id="ctrl-PR", label=<PR>];"#, "sub/");
        assert_eq!(h, r#""PR" [id="ctrl-PR", URL="sub/PR.html", label=<PR>];"#);
        let none: BTreeMap<String, u64> = [("E2".to_string(), 0)].into();
        assert!(link_plan(r#"a -> b [id="edge-E2"]"#, Some(&none)).contains("class=\"never\""));
    }

    #[test]
    fn the_prologue_is_dropped() {
        assert_eq!(
            inline("<?xml?>\n<!DOCTYPE svg>\n<svg a>\n</svg>\n"),
            "<svg a>\n</svg>"
        );
    }

    #[test]
    fn the_floor_keeps_the_smallest_text_at_10_px() {
        let svg = "<svg width=\"723pt\" height=\"527pt\"\n viewBox=\"0.00 0.00 723.20 526.75\" xmlns=\"x\">\n<g transform=\"scale(1 1) rotate(0)\"><text font-size=\"14.00\">a</text><text font-size=\"11.00\">b</text></g></svg>";
        // 11 units in 723.2 → 10 px at 657.5 px wide.
        assert_eq!(min_width_px(svg), Some(658));
        let halved = svg.replace("scale(1 1)", "scale(0.5 0.5)");
        assert_eq!(min_width_px(&halved), Some(1315));
        assert_eq!(min_width_px("<svg xmlns=\"x\"><text>a</text></svg>"), None);
        assert_eq!(min_width_px("<svg viewBox=\"0 0 10 10\"></svg>"), None);
    }
}

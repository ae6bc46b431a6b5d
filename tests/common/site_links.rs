//! A crawler over a generated doc site (files by path): every `href`,
//! `src` and `xlink:href` of every page, and every page of the search
//! index, must lead to a file of the site, and a `#fragment` to an element
//! with that `id` in it. Nothing may lead outside the site (it is offline).

use std::collections::{BTreeMap, BTreeSet};

/// The values of attribute `name="…"` in `html`.
fn attrs<'a>(html: &'a str, name: &str) -> Vec<&'a str> {
    let needle = format!(" {name}=\"");
    let mut out = Vec::new();
    let mut rest = html;
    while let Some(at) = rest.find(&needle) {
        let value = &rest[at + needle.len()..];
        let Some(end) = value.find('"') else { break };
        out.push(&value[..end]);
        rest = &value[end..];
    }
    out
}

fn unescape(s: &str) -> String {
    s.replace("&#45;", "-")
        .replace("&quot;", "\"")
        .replace("&#39;", "'")
        .replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&amp;", "&")
}

/// `base` (a file's folder, `/`-separated, `""` at the root) joined with a
/// relative link; `None` when it climbs out of the site.
fn join(base: &str, link: &str) -> Option<String> {
    let mut parts: Vec<&str> = base.split('/').filter(|p| !p.is_empty()).collect();
    for p in link.split('/') {
        match p {
            "" | "." => {}
            ".." => {
                parts.pop()?;
            }
            p => parts.push(p),
        }
    }
    Some(parts.join("/"))
}

/// Every link that does not resolve, as `page: link (why)`. `files` maps
/// each path of the site to its text.
#[allow(dead_code)] // each test binary compiles this module; not all use it
pub fn broken_links(files: &BTreeMap<String, String>) -> Vec<String> {
    let ids: BTreeMap<&str, BTreeSet<String>> = files
        .iter()
        .map(|(path, text)| {
            let set = attrs(text, "id").into_iter().map(unescape).collect();
            (path.as_str(), set)
        })
        .collect();
    let mut broken = Vec::new();
    let mut check = |page: &str, base: &str, link: &str| {
        let link = unescape(link);
        if link.contains("://") || link.starts_with("//") || link.starts_with("mailto:") {
            broken.push(format!("{page}: {link} (leads outside the site)"));
            return;
        }
        let (file, fragment) = match link.split_once('#') {
            Some((f, frag)) => (f, Some(frag)),
            None => (link.as_str(), None),
        };
        let target = if file.is_empty() {
            Some(page.to_string())
        } else {
            join(base, file)
        };
        let Some(target) = target else {
            broken.push(format!("{page}: {link} (climbs out of the site)"));
            return;
        };
        let Some(target_ids) = ids.get(target.as_str()) else {
            broken.push(format!("{page}: {link} (no file {target})"));
            return;
        };
        if let Some(f) = fragment {
            if !target_ids.contains(f) {
                broken.push(format!("{page}: {link} (no id `{f}` in {target})"));
            }
        }
    };
    for (path, text) in files {
        let base = path.rsplit_once('/').map(|(d, _)| d).unwrap_or("");
        if path.ends_with(".html") {
            for name in ["href", "src", "xlink:href"] {
                for link in attrs(text, name) {
                    check(path, base, link);
                }
            }
        }
        if path == "search.js" {
            // Each entry: ["name","kind","href from the root"].
            for line in text.lines().filter(|l| l.starts_with('[')) {
                let href = line
                    .trim_end_matches(',')
                    .trim_end_matches(']')
                    .rsplit("\",\"")
                    .next()
                    .unwrap_or("")
                    .trim_matches('"');
                check(path, "", href);
            }
        }
    }
    broken
}

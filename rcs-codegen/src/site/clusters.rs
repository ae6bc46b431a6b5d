//! The site of a large plan set (more than [`LARGE_SET`] controllers):
//! one drawing of a thousand controllers takes seconds to load, so the
//! index draws an overview instead — one node per cluster (a CPU of the
//! schedule, or, when a CPU runs more than [`CLUSTER_MAX`] controllers,
//! a connected part of its hierarchy) with its number of controllers and
//! the command links between clusters — and each cluster gets a page that
//! draws its controllers with the neighbours they command or are commanded
//! by. The controller and buffer tables move to pages of their own, of at
//! most [`LIST_PAGE`] rows each.
//!
//! Pages (in the set's folder): `cluster-<name>.html` per cluster,
//! `list-controllers[-N].html`, `list-buffers[-N].html`. A hyphen cannot occur in
//! a controller's name, so none of them can be a controller's page.

use super::html::{esc, finding, page};
use super::index::{buffers_table, controllers_table, graph_or_notice};
use super::plan::Placed;
use super::{ctrl_page, folder, root_of, SetDoc, Site, Svgs};
use crate::dot::{html, period, quoted};
use rcs_dsl::ir::Ir;
use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write;

/// Above this many controllers a set's index shows clusters instead of
/// the whole hierarchy and its tables.
pub const LARGE_SET: usize = 60;

/// The most controllers one cluster draws.
pub const CLUSTER_MAX: usize = 60;

/// Whether a set is documented cluster by cluster.
pub(super) fn is_large(ir: &Ir) -> bool {
    ir.controllers.len() > LARGE_SET
}

/// A group of controllers drawn together: a CPU, or part of one.
pub(super) struct Cluster {
    /// `CPU main` or `CPU main · C5` (part of CPU main under C5).
    pub title: String,
    /// The page's file name, in the set's folder.
    pub page: String,
    /// The CPU's name and period, for the tables.
    pub cpu: String,
    /// Controller indexes, each supervisor before its subordinates.
    pub members: Vec<usize>,
}

/// Rows per page of a large set's lists.
pub const LIST_PAGE: usize = 250;

/// The `k`th page (from 0) of a list whose first page is `first`:
/// `list-buffers.html`, `list-buffers-2.html`, …
pub(super) fn list_page(first: &str, k: usize) -> String {
    if k == 0 {
        first.to_string()
    } else {
        format!("{}-{}.html", first.trim_end_matches(".html"), k + 1)
    }
}

/// The page of a large set's buffer list showing buffer `b`.
pub(super) fn buffer_list_page(b: usize) -> String {
    list_page(BUFFERS_PAGE, b / LIST_PAGE)
}

/// The list pages of a large set, in its folder.
pub(super) const CONTROLLERS_PAGE: &str = "list-controllers.html";
pub(super) const BUFFERS_PAGE: &str = "list-buffers.html";

/// Controllers per cluster, in the schedule's order; within a CPU the
/// parts are ordered as their top controllers are in the hierarchy.
pub(super) fn clusters(ir: &Ir) -> Vec<Cluster> {
    let mut cpu_of: Vec<Option<usize>> = vec![None; ir.controllers.len()];
    let mut groups: Vec<(String, String, Vec<usize>)> = Vec::new();
    for (k, cpu) in ir.schedule.iter().enumerate() {
        let members: Vec<usize> = cpu.order.iter().map(|c| c.index()).collect();
        for &m in &members {
            cpu_of[m] = Some(k);
        }
        let label = format!("{} · {}", cpu.name, period(cpu.period_ns));
        groups.push((cpu.name.clone(), label, members));
    }
    // A set that fails its schedule check is not documented; still, no
    // controller may go missing.
    let rest: Vec<usize> = (0..ir.controllers.len())
        .filter(|c| cpu_of[*c].is_none())
        .collect();
    if !rest.is_empty() {
        for &m in &rest {
            cpu_of[m] = Some(groups.len());
        }
        groups.push(("unscheduled".into(), "none".into(), rest));
    }
    let mut out = Vec::new();
    let mut pages = BTreeSet::new();
    for (k, (name, label, members)) in groups.into_iter().enumerate() {
        let parts = if members.len() <= CLUSTER_MAX {
            vec![members]
        } else {
            split(ir, &members, &|c| cpu_of[c] == Some(k))
        };
        let several = parts.len() > 1;
        for members in parts {
            let top = &ir.controllers[members[0]].name;
            let (title, slug) = if several {
                (format!("CPU {name} · {top}"), format!("{name}.{top}"))
            } else {
                (format!("CPU {name}"), name.clone())
            };
            let mut page = format!("cluster-{}", file_safe(&slug));
            while !pages.insert(page.clone()) {
                page.push('_');
            }
            out.push(Cluster {
                title,
                page: format!("{page}.html"),
                cpu: label.clone(),
                members,
            });
        }
    }
    out
}

/// A CPU's controllers cut into connected parts of at most
/// [`CLUSTER_MAX`]: bottom-up, each controller gathers itself and what its
/// subordinates (on the same CPU) left over; while that is too many, the
/// largest subordinate's part becomes a cluster of its own.
fn split(ir: &Ir, members: &[usize], on_cpu: &dyn Fn(usize) -> bool) -> Vec<Vec<usize>> {
    let mut done = Vec::new();
    let mut seen = BTreeSet::new();
    for &m in members {
        let top = match ir.controllers[m].supervisor {
            Some(s) => !on_cpu(s.index()),
            None => true,
        };
        if top && !seen.contains(&m) {
            let rest = gather(ir, m, on_cpu, &mut seen, &mut done);
            done.push(rest);
        }
    }
    // Controllers in a cycle of supervisors (refused by the check) would
    // have no top: each its own part, so none is lost.
    for &m in members {
        if seen.insert(m) {
            done.push(vec![m]);
        }
    }
    let order: BTreeMap<usize, usize> = members.iter().enumerate().map(|(i, m)| (*m, i)).collect();
    done.sort_by_key(|p| p.first().and_then(|m| order.get(m)).copied());
    done
}

fn gather(
    ir: &Ir,
    c: usize,
    on_cpu: &dyn Fn(usize) -> bool,
    seen: &mut BTreeSet<usize>,
    done: &mut Vec<Vec<usize>>,
) -> Vec<usize> {
    seen.insert(c);
    let mut kids: Vec<Vec<usize>> = Vec::new();
    for s in &ir.controllers[c].subordinates {
        let s = s.index();
        if on_cpu(s) && !seen.contains(&s) {
            kids.push(gather(ir, s, on_cpu, seen, done));
        }
    }
    while 1 + kids.iter().map(Vec::len).sum::<usize>() > CLUSTER_MAX {
        // The largest part; the first of equals, so the cut is the same
        // from run to run.
        let Some(i) = (0..kids.len()).max_by_key(|i| (kids[*i].len(), std::cmp::Reverse(*i)))
        else {
            break;
        };
        done.push(kids.remove(i));
    }
    let mut part = vec![c];
    part.extend(kids.into_iter().flatten());
    part
}

/// A name made safe for a file name.
fn file_safe(s: &str) -> String {
    s.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '_' | '.' | '-') {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// The cluster of each controller (by index).
fn cluster_of(ir: &Ir, clusters: &[Cluster]) -> Vec<usize> {
    let mut of = vec![0; ir.controllers.len()];
    for (k, cl) in clusters.iter().enumerate() {
        for &m in &cl.members {
            of[m] = k;
        }
    }
    of
}

pub(super) fn overview_key(folder: &str) -> String {
    format!("{folder}clusters")
}

pub(super) fn cluster_key(folder: &str, cluster: &Cluster) -> String {
    format!("{folder}{}", cluster.page)
}

const HEAD: &str = "    node [fontname=\"Helvetica\", shape=box, style=rounded];\n";

/// The overview: a node per cluster (linking to its page, from the site's
/// root) and an edge per pair of clusters with command links between them.
pub(super) fn overview_graph(ir: &Ir, clusters: &[Cluster], folder: &str) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "// {} for system {}: clusters. Do not edit.",
        crate::GENERATED,
        ir.system
    );
    let _ = writeln!(out, "digraph {} {{", quoted(&ir.system));
    let _ = writeln!(
        out,
        "    graph [label={}, labelloc=t, fontname=\"Helvetica\", rankdir=TB];",
        quoted(&format!(
            "{} hierarchy: {} controllers in {} clusters",
            ir.system,
            ir.controllers.len(),
            clusters.len()
        ))
    );
    out.push_str(HEAD);
    for (k, cl) in clusters.iter().enumerate() {
        let _ = writeln!(
            out,
            "    \"k{k}\" [id={}, URL={}, label=<{}<BR/><FONT POINT-SIZE=\"9\">{} controllers</FONT>>, tooltip={}];",
            quoted(&cluster_id(cl)),
            quoted(&format!("{folder}{}", cl.page)),
            html(&cl.title),
            cl.members.len(),
            quoted(&format!("{} ({})", cl.title, cl.cpu))
        );
    }
    let of = cluster_of(ir, clusters);
    let mut links: BTreeMap<(usize, usize), usize> = BTreeMap::new();
    for (c, ctrl) in ir.controllers.iter().enumerate() {
        for s in &ctrl.subordinates {
            let (a, b) = (of[c], of[s.index()]);
            if a != b {
                *links.entry((a, b)).or_default() += 1;
            }
        }
    }
    for ((a, b), n) in links {
        let what = if n == 1 {
            "1 command link".to_string()
        } else {
            format!("{n} command links")
        };
        let _ = writeln!(
            out,
            "    \"k{a}\" -> \"k{b}\" [label={}, tooltip={}];",
            quoted(&n.to_string()),
            quoted(&what)
        );
    }
    out.push_str("}\n");
    out
}

/// The id of a cluster's node in the overview.
fn cluster_id(cl: &Cluster) -> String {
    cl.page.trim_end_matches(".html").to_string()
}

/// One cluster: its controllers (linking to their pages) and, dashed, the
/// controllers outside it that command or are commanded by one of them
/// (linking to their cluster's page). Links are from the set's folder.
pub(super) fn cluster_graph(ir: &Ir, clusters: &[Cluster], k: usize) -> String {
    let cl = &clusters[k];
    let of = cluster_of(ir, clusters);
    let mut out = String::new();
    let _ = writeln!(
        out,
        "// {} for system {}: {}. Do not edit.",
        crate::GENERATED,
        ir.system,
        cl.title
    );
    let _ = writeln!(out, "digraph {} {{", quoted(&cl.title));
    let _ = writeln!(
        out,
        "    graph [label={}, labelloc=t, fontname=\"Helvetica\", rankdir=TB];",
        quoted(&format!("{} · {}", ir.system, cl.title))
    );
    out.push_str(HEAD);
    let mut near: BTreeSet<usize> = BTreeSet::new();
    let mut edges: Vec<(usize, usize)> = Vec::new();
    for &m in &cl.members {
        let c = &ir.controllers[m];
        let mut label = html(&c.name);
        if let Some(t) = c.title.as_ref().filter(|t| !t.is_empty()) {
            let _ = write!(label, "<BR/><FONT POINT-SIZE=\"9\">{}</FONT>", html(t));
        }
        let _ = writeln!(
            out,
            "    {} [id={}, URL={}, label=<{label}>, tooltip={}];",
            quoted(&c.name),
            quoted(&crate::dot::ctrl_id(&c.name)),
            quoted(&ctrl_page(c)),
            quoted(&c.docs.join("\n"))
        );
        if let Some(s) = c.supervisor {
            if of[s.index()] != k {
                near.insert(s.index());
                edges.push((s.index(), m));
            }
        }
        for s in &c.subordinates {
            if of[s.index()] != k {
                near.insert(s.index());
            }
            edges.push((m, s.index()));
        }
    }
    for n in near {
        let c = &ir.controllers[n];
        let other = &clusters[of[n]];
        let _ = writeln!(
            out,
            "    {} [id={}, URL={}, style=\"rounded,dashed\", color=gray50, fontcolor=gray30, label=<{}<BR/><FONT POINT-SIZE=\"8\">in {}</FONT>>, tooltip={}];",
            quoted(&c.name),
            quoted(&format!("near-{}", c.name)),
            quoted(&other.page),
            html(&c.name),
            html(&other.title),
            quoted(&format!("{} is drawn in {}", c.name, other.title))
        );
    }
    for (a, b) in edges {
        let dashed = if of[a] != k || of[b] != k {
            " [style=dashed, color=gray50]"
        } else {
            ""
        };
        let _ = writeln!(
            out,
            "    {} -> {}{dashed};",
            quoted(&ir.controllers[a].name),
            quoted(&ir.controllers[b].name)
        );
    }
    out.push_str("}\n");
    out
}

/// The index's part for a large set: the overview and a table of the
/// clusters, with links to the lists of all controllers and buffers.
pub(super) fn index_section(site: &Site, set: &SetDoc, svgs: &Svgs, placed: &Placed) -> String {
    let ir = set.ir;
    let folder = folder(site, set);
    let clusters = clusters(ir);
    let mut body = String::new();
    let _ = writeln!(
        body,
        "<p class=\"large\">{} controllers and {} buffers: more than {LARGE_SET} controllers, so the hierarchy is drawn cluster by cluster (a CPU, or a part of a CPU's hierarchy of at most {CLUSTER_MAX} controllers). All <a href=\"{folder}{CONTROLLERS_PAGE}\">controllers</a> and <a href=\"{folder}{BUFFERS_PAGE}\">buffers</a> have pages of their own.</p>",
        ir.controllers.len(),
        ir.buffers.len()
    );
    body.push_str(&graph_or_notice(
        svgs.get(&overview_key(&folder)),
        &format!("the {} clusters", ir.system),
    ));
    for d in &placed.set {
        body.push_str(&finding(d));
    }
    body.push_str("<h3>Clusters</h3>\n<table>\n<tr><th>cluster</th><th>CPU</th><th>controllers</th><th>top</th></tr>\n");
    for cl in &clusters {
        let top = &ir.controllers[cl.members[0]];
        let _ = writeln!(
            body,
            "<tr><td><a href=\"{folder}{}\">{}</a></td><td>{}</td><td>{}</td><td><a href=\"{folder}{}\">{}</a></td></tr>",
            cl.page,
            esc(&cl.title),
            esc(&cl.cpu),
            cl.members.len(),
            ctrl_page(top),
            esc(&top.name)
        );
    }
    body.push_str("</table>\n");
    body
}

/// The extra pages of a large set: one per cluster and the two lists.
pub(super) fn pages(site: &Site, set: &SetDoc, svgs: &Svgs) -> Vec<crate::OutputFile> {
    let ir = set.ir;
    let folder = folder(site, set);
    let root = root_of(site);
    let nav = |what: &str| {
        format!(
            "<nav><a href=\"{root}index.html\">{}</a> › {}</nav>\n",
            esc(&ir.system),
            esc(what)
        )
    };
    let clusters = clusters(ir);
    let mut files = Vec::new();
    for cl in &clusters {
        let mut body = nav(&cl.title);
        let _ = writeln!(
            body,
            "<p>{} controllers on CPU {}; dashed: the controllers of other clusters that command or are commanded by them.</p>",
            cl.members.len(),
            esc(&cl.cpu)
        );
        body.push_str(&graph_or_notice(
            svgs.get(&cluster_key(&folder, cl)),
            &cl.title,
        ));
        body.push_str(&controllers_table(ir, "", &cl.members, None));
        files.push(crate::OutputFile {
            path: cluster_key(&folder, cl),
            contents: page(&format!("{} · {}", ir.system, cl.title), root, &body),
        });
    }
    let lists = [
        ("controllers", ir.controllers.len(), CONTROLLERS_PAGE),
        ("buffers", ir.buffers.len(), BUFFERS_PAGE),
    ];
    for (what, count, first) in lists {
        let all: Vec<usize> = (0..count).collect();
        let chunks: Vec<&[usize]> = all.chunks(LIST_PAGE).collect();
        let name = |k: usize| list_page(first, k);
        for (k, chunk) in chunks.iter().enumerate() {
            let mut body = nav(what);
            if chunks.len() > 1 {
                let links: Vec<String> = (0..chunks.len())
                    .map(|j| {
                        let range = format!(
                            "{}–{}",
                            j * LIST_PAGE + 1,
                            (j * LIST_PAGE + LIST_PAGE).min(count)
                        );
                        if j == k {
                            format!("<b>{range}</b>")
                        } else {
                            format!("<a href=\"{}\">{range}</a>", name(j))
                        }
                    })
                    .collect();
                let _ = writeln!(
                    body,
                    "<p class=\"pager\">{count} {what}: {}</p>",
                    links.join(" · ")
                );
            }
            body.push_str(&if what == "controllers" {
                controllers_table(ir, "", chunk, None)
            } else {
                buffers_table(ir, "", chunk)
            });
            files.push(crate::OutputFile {
                path: format!("{folder}{}", name(k)),
                contents: page(&format!("{} · {what}", ir.system), root, &body),
            });
        }
    }
    files
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ir_of(n: usize) -> Ir {
        let mut text = String::new();
        // A chain of n controllers, each commanding the next, and one
        // extra subordinate under the first.
        for i in 0..n {
            let subs = if i + 1 < n {
                format!("subordinates C{}\n", i + 1)
            } else {
                String::new()
            };
            let _ = writeln!(
                text,
                "controller C{i} {{\n{subs}command GO\nplan GO {{\nE0: *0 when new_command -> Done\n}}\n}}"
            );
        }
        let set = rcs_dsl::PlanSet::from_texts("t", [("t.rcs", text.as_str())], None);
        let checked = rcs_dsl::check(&set, &rcs_dsl::Options::default());
        let errors: Vec<&str> = checked
            .diagnostics
            .iter()
            .filter(|d| d.severity == rcs_dsl::Severity::Error)
            .map(|d| d.message.as_str())
            .collect();
        checked.ir.unwrap_or_else(|| panic!("{errors:?}"))
    }

    #[test]
    fn a_large_cpu_is_cut_into_connected_parts_of_at_most_the_maximum() {
        let ir = ir_of(150);
        let cl = clusters(&ir);
        let sizes: Vec<usize> = cl.iter().map(|c| c.members.len()).collect();
        assert!(sizes.iter().all(|s| *s <= CLUSTER_MAX), "{sizes:?}");
        assert_eq!(sizes.iter().sum::<usize>(), 150);
        let mut all: Vec<usize> = cl.iter().flat_map(|c| c.members.clone()).collect();
        all.sort();
        assert_eq!(all, (0..150).collect::<Vec<_>>());
        // Connected: every member but the first has its supervisor inside.
        for c in &cl {
            for m in &c.members[1..] {
                let sup = ir.controllers[*m].supervisor.unwrap().index();
                assert!(c.members.contains(&sup), "{} {m}", c.title);
            }
        }
        assert!(
            cl.len() >= 3 && cl[0].title.starts_with("CPU "),
            "{}",
            cl[0].title
        );
        let pages: BTreeSet<&str> = cl.iter().map(|c| c.page.as_str()).collect();
        assert_eq!(pages.len(), cl.len());
    }

    #[test]
    fn a_small_cpu_is_one_cluster() {
        let ir = ir_of(5);
        let cl = clusters(&ir);
        assert_eq!(cl.len(), 1);
        assert_eq!(cl[0].members, vec![0, 1, 2, 3, 4]);
    }
}

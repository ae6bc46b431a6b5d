//! IR (+ findings, run counts, rendered graphs) → the pages of the doc site
//! that `rcsc doc` writes: a back end like [`crate::dot`] and
//! [`crate::table`], pure, returning files for the [`crate::writer`].
//!
//! Two passes, because only the CLI runs Graphviz:
//!
//! ```text
//! sets ──graphs()──▶ DOT per graph (links added) ──dot -Tsvg (CLI)──▶ SVG
//! sets + SVGs ──pages()──▶ index.html, <CTRL>.html, <CTRL>.<VERB>.html,
//!                           site.css, site.js, search.js
//! ```
//!
//! A set of more than [`LARGE_SET`] controllers is drawn cluster by
//! cluster ([`clusters`]); with a diff (`rcsc doc --diff`) the site gets a
//! Changes page ([`changes`]).
//!
//! The pages link by the `id`s [`crate::dot`] gives nodes and edges
//! (`node-S1`, `edge-E3`, `ctrl-PR`): [`svg`] turns each id into a link
//! (`URL`) and, with run counts, a line width and a class, before the DOT
//! is rendered, so the site does not depend on the graphs' layout. A graph
//! without SVG (Graphviz missing) is replaced by a notice.
//!
//! Anchors a page offers: `row-E<N>` (a table row), `state-<S>` (a state),
//! `L<line>` (a source line), `edge-E<N>` / `node-<S>` (in the SVG).

mod changes;
mod clusters;
mod controller;
mod html;
mod index;
mod markdown;
mod plan;
pub mod runs;
mod svg;
mod types;

pub use clusters::{CLUSTER_MAX, LARGE_SET, LIST_PAGE};
pub use runs::RunCounts;

use crate::OutputFile;
use rcs_dsl::ir::{Controller, Ir, Plan};
use rcs_dsl::Diagnostic;
use std::collections::BTreeMap;

/// One plan set to document.
pub struct SetDoc<'a> {
    pub ir: &'a Ir,
    /// The text of each file, in `FileId` order (parallel to `ir.files`).
    pub sources: Vec<&'a str>,
    /// The findings of `rcsc check` (warnings and analysis findings).
    pub findings: &'a [Diagnostic],
    /// Row hits and cycles per state, from scenarios or traces.
    pub runs: Option<&'a RunCounts>,
}

/// Every plan set of the site; `shared`: each set gets its own
/// `<system>/` folder (a workspace or several sets), as `rcsc build` does.
pub struct Site<'a> {
    pub sets: Vec<SetDoc<'a>>,
    pub shared: bool,
    /// With `rcsc doc --diff`: what the plans change, for the Changes page.
    pub changes: Option<Changes<'a>>,
}

/// A semantic diff of the documented plans against an older version.
pub struct Changes<'a> {
    pub diff: &'a rcs_dsl::diff::PlanSetDiff,
    /// The older version, as the user named it (`HEAD~1`, a path).
    pub against: String,
}

/// A graph to render: its key (for [`pages`]) and its DOT text.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct GraphSource {
    pub key: String,
    pub dot: String,
}

/// Rendered graphs by key; a key without an entry is drawn as a notice.
pub type Svgs = BTreeMap<String, String>;

/// The folder of a set's pages, `""` or `<system>/`.
fn folder(site: &Site, set: &SetDoc) -> String {
    crate::set_folder(set.ir, site.shared)
}

fn hierarchy_key(folder: &str) -> String {
    format!("{folder}hierarchy")
}

fn plan_key(folder: &str, ctrl: &Controller, plan: &Plan) -> String {
    format!("{folder}{}", plan_page(ctrl, plan))
}

/// The page of a controller, relative to its set's folder.
fn ctrl_page(ctrl: &Controller) -> String {
    format!("{}.html", ctrl.name)
}

/// The page of a plan, relative to its set's folder.
fn plan_page(ctrl: &Controller, plan: &Plan) -> String {
    format!(
        "{}.{}.html",
        ctrl.name,
        ctrl.commands[plan.verb.index()].name
    )
}

/// Every graph of the site, with its links (and run weights) in the DOT.
pub fn graphs(site: &Site) -> Vec<GraphSource> {
    let mut out = Vec::new();
    for set in &site.sets {
        let folder = folder(site, set);
        if clusters::is_large(set.ir) {
            out.extend(cluster_graphs(set.ir, &folder));
        } else {
            out.push(GraphSource {
                key: hierarchy_key(&folder),
                dot: svg::link_hierarchy(&crate::dot::hierarchy_graph(set.ir), &folder),
            });
        }
        let placed = plan::place_findings(set);
        for (ci, ctrl) in set.ir.controllers.iter().enumerate() {
            for (pi, plan) in ctrl.plans.iter().enumerate() {
                let weights = set.runs.map(|r| r.row_weights(&ctrl.name, plan));
                let marks = crate::dot::RowMarks {
                    hits: weights.clone(),
                    findings: placed.row_severities(ci, pi, plan),
                };
                let dot = crate::dot::plan_graph_marked(set.ir, ctrl, plan, &marks);
                out.push(GraphSource {
                    key: plan_key(&folder, ctrl, plan),
                    dot: svg::link_plan(&dot, weights.as_ref()),
                });
            }
        }
    }
    if let Some(c) = &site.changes {
        out.extend(changes::graphs(c));
    }
    out
}

/// A large set's graphs: the overview of its clusters, then each cluster.
fn cluster_graphs(ir: &Ir, folder: &str) -> Vec<GraphSource> {
    let all = clusters::clusters(ir);
    let mut out = vec![GraphSource {
        key: clusters::overview_key(folder),
        dot: clusters::overview_graph(ir, &all, folder),
    }];
    for (k, cl) in all.iter().enumerate() {
        out.push(GraphSource {
            key: clusters::cluster_key(folder, cl),
            dot: clusters::cluster_graph(ir, &all, k),
        });
    }
    out
}

/// Where a set's buffer `b` (index) is listed, from the site's root: the
/// index, or the page of a large set's list of buffers that shows it.
fn buffers_href(site: &Site, set: &SetDoc, b: usize) -> String {
    if clusters::is_large(set.ir) {
        format!("{}{}", folder(site, set), clusters::buffer_list_page(b))
    } else {
        "index.html".into()
    }
}

/// Every page of the site, given the rendered graphs.
pub fn pages(site: &Site, svgs: &Svgs) -> Vec<OutputFile> {
    let placed: Vec<plan::Placed> = site.sets.iter().map(plan::place_findings).collect();
    let mut files = vec![
        OutputFile {
            path: "site.css".into(),
            contents: format!("/* {} */\n{}", crate::GENERATED, include_str!("site.css")),
        },
        OutputFile {
            path: "site.js".into(),
            contents: format!("// {}\n{}", crate::GENERATED, include_str!("site.js")),
        },
        OutputFile {
            path: "search.js".into(),
            contents: index::search_js(site),
        },
        OutputFile {
            path: "index.html".into(),
            contents: index::index_page(site, svgs, &placed),
        },
    ];
    if let Some(c) = &site.changes {
        files.push(OutputFile {
            path: changes::CHANGES_PAGE.into(),
            contents: changes::changes_page(site, c, svgs),
        });
    }
    for (set, placed) in site.sets.iter().zip(&placed) {
        let folder = folder(site, set);
        if clusters::is_large(set.ir) {
            files.extend(clusters::pages(site, set, svgs));
        }
        for (ty, instances) in types::types(set.ir) {
            files.push(OutputFile {
                path: format!("{folder}{}", types::type_page_name(ty)),
                contents: types::type_page(site, set, ty, &instances),
            });
        }
        for (ci, ctrl) in set.ir.controllers.iter().enumerate() {
            files.push(OutputFile {
                path: format!("{folder}{}", ctrl_page(ctrl)),
                contents: controller::controller_page(site, set, ci, placed),
            });
            for (pi, plan) in ctrl.plans.iter().enumerate() {
                let key = plan_key(&folder, ctrl, plan);
                files.push(OutputFile {
                    contents: plan::plan_page(site, set, ci, pi, svgs.get(&key), placed),
                    path: key,
                });
            }
        }
    }
    files
}

/// `../` from a set's folder back to the site's root.
fn root_of(site: &Site) -> &'static str {
    if site.shared {
        "../"
    } else {
        ""
    }
}

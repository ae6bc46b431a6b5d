//! What a rendered graph looks like, read from Graphviz's `-Tjson` output
//! (the xdot drawing ops, which carry every text's exact anchor, alignment,
//! width and font size as Graphviz measured them) and its `-Tsvg` header,
//! and the checks a reader's eye makes: no two texts overlap, no text lies
//! on another node's shape or on an edge's line, nothing leaves the
//! canvas, and the smallest text stays legible at the site's page width.
//!
//! Kept apart from the corpus walk (`main.rs`) so the detector itself can
//! be tested on hand-made drawings (see the tests at the bottom).

use serde_json::Value;

/// The width of the doc site's content column, in CSS px: the browser
/// tests' 1,280-px window less `main`'s padding (1.5em each side, 48 px)
/// and a scroll bar. `.graph svg { max-width: 100% }` in `site.css`
/// shrinks a wider graph to this.
pub const PAGE_WIDTH_PX: f64 = 1200.0;
/// The smallest text a reader is asked to read at page width, in px.
pub const MIN_TEXT_PX: f64 = 10.0;
/// Browsers draw `Helvetica` text in their own font (Helvetica itself,
/// Arial or Liberation Sans, all of one set of widths), with their own
/// hinting and rounding. Widths Graphviz measured are taken this much
/// wider, from their anchor, to be on the safe side. (A system with none
/// of those fonts falls back to a wider one, DejaVu Sans; no margin short
/// of 15% covers that.)
const WIDTH_MARGIN: f64 = 1.03;
/// SVG user units (points) to CSS px at 100%.
const PX_PER_PT: f64 = 4.0 / 3.0;

/// An axis-aligned box, Graphviz coordinates (points, y up).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rect {
    pub x0: f64,
    pub y0: f64,
    pub x1: f64,
    pub y1: f64,
}

impl Rect {
    fn overlaps(&self, o: &Rect, gap: f64) -> bool {
        self.x0 < o.x1 - gap && o.x0 < self.x1 - gap && self.y0 < o.y1 - gap && o.y0 < self.y1 - gap
    }
    fn contains(&self, x: f64, y: f64) -> bool {
        x > self.x0 && x < self.x1 && y > self.y0 && y < self.y1
    }
}

/// One piece of text: where it is, how big, and who drew it.
#[derive(Clone, Debug)]
pub struct Text {
    pub text: String,
    pub size: f64,
    pub rect: Rect,
    /// Index of the object (node, edge, cluster, graph) that drew it.
    pub owner: String,
    /// Where it ends as Graphviz measured it (without the margin).
    raw_x1: f64,
}

/// A node's outline: an ellipse (centre and radii) or a polygon's box.
#[derive(Clone, Debug)]
pub enum Shape {
    Ellipse { cx: f64, cy: f64, rx: f64, ry: f64 },
    Polygon(Vec<(f64, f64)>),
}

impl Shape {
    /// Whether the text box crosses this outline's area (the filled
    /// region: a label inside someone else's circle counts).
    fn hits(&self, r: &Rect) -> bool {
        match self {
            Shape::Ellipse { cx, cy, rx, ry } => {
                // The point of the box nearest the centre, inside the ellipse?
                let nx = cx.clamp(r.x0, r.x1);
                let ny = cy.clamp(r.y0, r.y1);
                let (dx, dy) = ((nx - cx) / rx, (ny - cy) / ry);
                dx * dx + dy * dy < 0.98
            }
            Shape::Polygon(pts) => bounds(pts).is_some_and(|b| b.overlaps(r, 0.5)),
        }
    }
    fn bounds(&self) -> Rect {
        match self {
            Shape::Ellipse { cx, cy, rx, ry } => Rect {
                x0: cx - rx,
                y0: cy - ry,
                x1: cx + rx,
                y1: cy + ry,
            },
            Shape::Polygon(pts) => bounds(pts).unwrap_or(Rect {
                x0: 0.0,
                y0: 0.0,
                x1: 0.0,
                y1: 0.0,
            }),
        }
    }
}

fn bounds(pts: &[(f64, f64)]) -> Option<Rect> {
    let first = pts.first()?;
    let mut r = Rect {
        x0: first.0,
        y0: first.1,
        x1: first.0,
        y1: first.1,
    };
    for (x, y) in pts {
        r.x0 = r.x0.min(*x);
        r.x1 = r.x1.max(*x);
        r.y0 = r.y0.min(*y);
        r.y1 = r.y1.max(*y);
    }
    Some(r)
}

/// A rendered graph: its canvas, texts, node outlines and edge lines.
#[derive(Debug, Default)]
pub struct Drawing {
    /// The graph's bounding box, points.
    pub width: f64,
    pub height: f64,
    /// The SVG's `width` attribute, points (the canvas plus its margin).
    pub svg_width: f64,
    pub texts: Vec<Text>,
    /// (owner, outline) of every node.
    pub shapes: Vec<(String, Shape)>,
    /// (owner, points along the line) of every edge, arrowheads included.
    pub lines: Vec<(String, Vec<(f64, f64)>)>,
}

fn num(v: &Value) -> f64 {
    v.as_f64().unwrap_or(0.0)
}

fn points(op: &Value) -> Vec<(f64, f64)> {
    op["points"]
        .as_array()
        .map(|a| a.iter().map(|p| (num(&p[0]), num(&p[1]))).collect())
        .unwrap_or_default()
}

/// Points along a cubic B-spline given as Graphviz's control points
/// (1 + 3n of them): the control points and eight samples per piece.
fn sample_bezier(pts: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    let mut i = 0;
    while i + 3 < pts.len() {
        let [p0, p1, p2, p3] = [pts[i], pts[i + 1], pts[i + 2], pts[i + 3]];
        for k in 0..=8 {
            let t = k as f64 / 8.0;
            let u = 1.0 - t;
            let b = |a: f64, b: f64, c: f64, d: f64| {
                u * u * u * a + 3.0 * u * u * t * b + 3.0 * u * t * t * c + t * t * t * d
            };
            out.push((b(p0.0, p1.0, p2.0, p3.0), b(p0.1, p1.1, p2.1, p3.1)));
        }
        i += 3;
    }
    out
}

impl Drawing {
    /// Read `dot -Tjson` output and the `width="…pt"` of `dot -Tsvg`'s.
    pub fn parse(json: &str, svg: &str) -> Result<Drawing, String> {
        let v: Value = serde_json::from_str(json).map_err(|e| format!("json: {e}"))?;
        let bb: Vec<f64> = v["bb"]
            .as_str()
            .ok_or("no bb")?
            .split(',')
            .map(|s| s.parse::<f64>().map_err(|e| format!("bb: {e}")))
            .collect::<Result<_, _>>()?;
        let mut d = Drawing {
            width: bb[2],
            height: bb[3],
            svg_width: svg_width(svg)?,
            ..Drawing::default()
        };
        d.read_ops(&v, "graph", false);
        for o in v["objects"].as_array().into_iter().flatten() {
            let owner = format!("object {}", o["name"].as_str().unwrap_or("?"));
            // Clusters are objects with `nodes`; their outline is a frame,
            // not a shape labels must keep off.
            let is_node = o.get("nodes").is_none() && o.get("_subgraph_cnt").is_none();
            d.read_ops(o, &owner, is_node);
        }
        for e in v["edges"].as_array().into_iter().flatten() {
            let owner = format!("edge {}", e["_gvid"]);
            d.read_ops(e, &owner, false);
            let mut line = Vec::new();
            for key in ["_draw_", "_hdraw_", "_tdraw_"] {
                for op in e[key].as_array().into_iter().flatten() {
                    match op["op"].as_str() {
                        Some("b" | "B") => line.extend(sample_bezier(&points(op))),
                        Some("p" | "P" | "L") => line.extend(points(op)),
                        _ => {}
                    }
                }
            }
            d.lines.push((owner, line));
        }
        Ok(d)
    }

    fn read_ops(&mut self, o: &Value, owner: &str, is_node: bool) {
        for key in ["_ldraw_", "_hldraw_", "_tldraw_", "_draw_"] {
            let mut size = 14.0;
            for op in o[key].as_array().into_iter().flatten() {
                match op["op"].as_str() {
                    Some("F") => size = num(&op["size"]),
                    Some("T") => {
                        let (x, y) = (num(&op["pt"][0]), num(&op["pt"][1]));
                        let w = num(&op["width"]) * WIDTH_MARGIN;
                        let x0 = match op["align"].as_str() {
                            Some("l") => x,
                            Some("r") => x - w,
                            _ => x - w / 2.0,
                        };
                        // Spans of one line of one label (a colour
                        // change) are one text: join them.
                        if let Some(last) = self.texts.last_mut().filter(|t| {
                            t.owner == owner
                                && (t.rect.y0 - (y - 0.21 * size)).abs() < 0.01
                                && (t.raw_x1 - x0).abs() < 0.5
                        }) {
                            last.text.push_str(op["text"].as_str().unwrap_or(""));
                            last.raw_x1 = x0 + w / WIDTH_MARGIN;
                            last.rect.x1 =
                                last.rect.x0 + (last.raw_x1 - last.rect.x0) * WIDTH_MARGIN;
                            continue;
                        }
                        self.texts.push(Text {
                            raw_x1: x0 + w / WIDTH_MARGIN,
                            text: op["text"].as_str().unwrap_or("").to_string(),
                            size,
                            // Ascent above the baseline, descent under it.
                            rect: Rect {
                                x0,
                                y0: y - 0.21 * size,
                                x1: x0 + w,
                                y1: y + 0.79 * size,
                            },
                            owner: owner.to_string(),
                        });
                    }
                    Some("e" | "E") if is_node && key == "_draw_" => {
                        let r = &op["rect"];
                        self.shapes.push((
                            owner.to_string(),
                            Shape::Ellipse {
                                cx: num(&r[0]),
                                cy: num(&r[1]),
                                rx: num(&r[2]),
                                ry: num(&r[3]),
                            },
                        ));
                    }
                    Some("p" | "P") if is_node && key == "_draw_" => {
                        self.shapes
                            .push((owner.to_string(), Shape::Polygon(points(op))));
                    }
                    _ => {}
                }
            }
        }
    }

    /// Everything wrong with the drawing, one line each; empty: legible.
    pub fn problems(&self) -> Vec<String> {
        let mut out = Vec::new();
        let t = &self.texts;
        for (i, a) in t.iter().enumerate() {
            for b in &t[i + 1..] {
                if a.rect.overlaps(&b.rect, 0.0) {
                    out.push(format!(
                        "text {:?} ({}) overlaps text {:?} ({})",
                        a.text, a.owner, b.text, b.owner
                    ));
                }
            }
            for (owner, shape) in &self.shapes {
                if *owner != a.owner && shape.hits(&a.rect) {
                    out.push(format!("text {:?} ({}) lies on {owner}", a.text, a.owner));
                }
            }
            for (owner, line) in &self.lines {
                if line.iter().any(|(x, y)| a.rect.contains(*x, *y)) {
                    out.push(format!(
                        "text {:?} ({}) is crossed by the line of {owner}",
                        a.text, a.owner
                    ));
                }
            }
            // The SVG's canvas: the bounding box and the `pad` around it.
            let pad = ((self.svg_width - self.width) / 2.0).max(0.0);
            let canvas = Rect {
                x0: -pad - 0.5,
                y0: -pad - 0.5,
                x1: self.width + pad + 0.5,
                y1: self.height + pad + 0.5,
            };
            if !(canvas.contains(a.rect.x0, a.rect.y0) && canvas.contains(a.rect.x1, a.rect.y1)) {
                out.push(format!("text {:?} ({}) leaves the canvas", a.text, a.owner));
            }
        }
        for (owner, shape) in &self.shapes {
            let b = shape.bounds();
            if b.x0 < -0.5 || b.y0 < -0.5 || b.x1 > self.width + 0.5 || b.y1 > self.height + 0.5 {
                out.push(format!("the outline of {owner} leaves the canvas"));
            }
        }
        if let Some(small) = t.iter().min_by(|a, b| a.size.total_cmp(&b.size)) {
            let px = small.size * PX_PER_PT * self.scale();
            if px < MIN_TEXT_PX {
                out.push(format!(
                    "the smallest text, {:?} at {} pt, is {px:.1} px high at page width \
                     (the graph is {:.0} px wide, shown {:.0}%)",
                    small.text,
                    small.size,
                    self.svg_width * PX_PER_PT,
                    self.scale() * 100.0
                ));
            }
        }
        out
    }

    /// How much the site shrinks the graph to fit its page (1: not at all).
    pub fn scale(&self) -> f64 {
        (PAGE_WIDTH_PX / (self.svg_width * PX_PER_PT)).min(1.0)
    }
}

/// The `width="123pt"` of Graphviz's `<svg>` element.
fn svg_width(svg: &str) -> Result<f64, String> {
    let at = svg.find("<svg").ok_or("no <svg> element")?;
    let rest = &svg[at..];
    let w = rest.find(" width=\"").ok_or("no svg width")? + 8;
    let end = rest[w..].find('"').ok_or("unterminated svg width")?;
    rest[w..w + end]
        .trim_end_matches("pt")
        .parse()
        .map_err(|e| format!("svg width {:?}: {e}", &rest[w..w + end]))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A hand-made drawing in `-Tjson`'s form: two labels of two edges
    /// printed over each other (PRIM.GOTO's E2 over E3), one label inside
    /// another node's circle, a line through a label, a text off the canvas.
    const TWO_LABELS: &str = r#"{
      "bb": "0,0,300,100",
      "objects": [
        {"_gvid": 0, "name": "S1",
         "_draw_": [{"op": "e", "rect": [50, 50, 20, 20]}],
         "_ldraw_": [{"op": "F", "size": 14, "face": "Helvetica"},
                     {"op": "T", "pt": [50, 46], "align": "c", "width": 14, "text": "S1"}]}
      ],
      "edges": [
        {"_gvid": 0, "_draw_": [{"op": "b", "points": [[70,50],[100,80],[130,80],[160,50]]}],
         "_ldraw_": [{"op": "F", "size": 10, "face": "Helvetica"},
                     {"op": "T", "pt": [120, 60], "align": "c", "width": 60, "text": "E2: new_command"}]},
        {"_gvid": 1, "_draw_": [],
         "_ldraw_": [{"op": "F", "size": 10, "face": "Helvetica"},
                     {"op": "T", "pt": [125, 64], "align": "l", "width": 60, "text": "E3: SERVO.done"},
                     {"op": "T", "pt": [45, 50], "align": "l", "width": 10, "text": "x"},
                     {"op": "T", "pt": [290, 90], "align": "l", "width": 40, "text": "far"}]}
      ]
    }"#;

    #[test]
    fn the_detector_finds_what_a_reader_would() {
        let d = Drawing::parse(TWO_LABELS, r#"<svg width="308pt" height="108pt">"#).unwrap();
        let p = d.problems().join("\n");
        assert!(
            p.contains(
                r#"text "E2: new_command" (edge 0) overlaps text "E3: SERVO.done" (edge 1)"#
            ),
            "{p}"
        );
        assert!(p.contains(r#"text "x" (edge 1) lies on object S1"#), "{p}");
        assert!(
            p.contains(r#"text "S1" (object S1) overlaps text "x" (edge 1)"#),
            "{p}"
        );
        assert!(
            p.contains(r#"text "far" (edge 1) leaves the canvas"#),
            "{p}"
        );
        assert!(
            p.contains(r#"text "E2: new_command" (edge 0) is crossed by the line of edge 0"#),
            "{p}"
        );
        assert!(!p.contains("smallest"), "{p}");
    }

    #[test]
    fn a_wide_graph_is_shrunk_below_legibility() {
        let json = r#"{"bb": "0,0,3000,50", "objects": [{"name": "a",
            "_ldraw_": [{"op": "F", "size": 8}, {"op": "T", "pt": [100, 20], "align": "c", "width": 10, "text": "jobs"}]}]}"#;
        let d = Drawing::parse(json, r#"<svg width="3008pt">"#).unwrap();
        let p = d.problems().join("\n");
        assert!(
            p.contains(r#"the smallest text, "jobs" at 8 pt, is 3.2 px"#),
            "{p}"
        );
        // Narrow enough, the same text is fine.
        let d = Drawing::parse(&json.replace("3000", "600"), r#"<svg width="608pt">"#).unwrap();
        assert!(d.problems().is_empty(), "{:?}", d.problems());
    }
}

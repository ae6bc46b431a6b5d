//! Part of `tests/site_browser.rs`: the doc site looked at as a person
//! would (issue 29, items 2 and 5). At a 1,400-px window, Chromium shows
//! the index (of `plans/`, and of a 60-controller set whose hierarchy is
//! far wider than the page), a controller page, a plan page with a
//! finding, a page with run counts (`--coverage`) and the Changes page
//! (`--diff`); on each the
//! test asserts through WebDriver that nothing is wider than the window
//! and that no graph text is drawn under 10 px, and keeps a screenshot,
//! printing its path for a person to look at. Then the full-size view of a
//! graph (`site.js`): opened by its button, the graph at natural size,
//! zoomed by the buttons and the wheel, panned by a drag, closed by Esc;
//! opened by a click on the graph's background, a link in it still leads
//! to its row.
//!
//! How text size is measured: an SVG `text`'s computed `font-size` is in
//! the text's own user units; its screen CTM (`getScreenCTM()`) maps those
//! units to CSS px as drawn, through the viewBox scaling of the SVG's
//! rendered width, Graphviz's group transform and any transform of the
//! full-size view. The font size times the CTM's scale is the text's em in
//! CSS px as rendered, the same measure as `font-size` of HTML text. (A
//! text's bounding-box height is not: it adds the font's ascent and
//! descent, and differs by font.) The test also checks the CTM against the
//! SVG's rendered width over its viewBox width, so a CTM that missed the
//! page's shrinking could not pass unnoticed.

use super::common::scratch;
use super::{
    browser, build_site, console_errors, file_url, screenshot, screenshots, session_sized,
};
use fantoccini::actions::{
    InputSource, MouseActions, PointerAction, WheelAction, WheelActions, MOUSE_BUTTON_LEFT,
};
use fantoccini::key::Key;
use fantoccini::{Client, Locator};
use std::path::Path;
use std::time::Duration;

/// The window the issue asks for: 1,400 CSS px wide.
const WINDOW_WIDTH: f64 = 1400.0;
/// The smallest graph text allowed, in CSS px.
const MIN_TEXT_PX: f64 = 10.0;

/// A plan set with a finding (`shadowed_row`, allowed to warn) and long
/// conditions, for a plan page that shows a warning on its graph.
const VALVE: &str = "\
/// Opens a valve to a set point and holds it there.
controller VALVE {
    reads flow: Flow
    command OPEN(target: f64)
    status OPENING
    status HOLDING
    plan OPEN {
        /// Start opening.
        E0: *0 when new_command -> S1 { report OPENING }
        E1: S1 when flow.rate > cmd.target && flow.pressure < 4.5 && flow.temperature < 80.0 -> S2 { report HOLDING }
        /// Never fires: E1 takes every cycle it could.
        E2: S1 when flow.rate > cmd.target && flow.pressure < 4.5 && flow.temperature < 80.0 && flow.rate > 0.0 -> Done
        E3: S2 when flow.rate < cmd.target * 0.9 || flow.pressure > 5.5 -> S1 { report OPENING }
        E4: S2 when flow.closed -> Done
        E5: *5 when plan_cycles > 500 -> Error
    }
}
buffer Flow { rate: f64, pressure: f64, temperature: f64, closed: bool }
";

/// What a page measures in the browser.
#[derive(Debug)]
struct Measure {
    inner_width: f64,
    client_width: f64,
    scroll_width: f64,
    graphs: u64,
    texts: u64,
    /// The smallest graph text as rendered, in CSS px, and what it says.
    smallest_px: Option<f64>,
    smallest_text: Option<String>,
    /// Graphs whose CTM disagrees with rendered width / viewBox width.
    scale_mismatches: Vec<String>,
}

impl Measure {
    fn from(v: &serde_json::Value) -> Measure {
        let num = |k: &str| v[k].as_f64().unwrap_or_else(|| panic!("{k} in {v}"));
        Measure {
            inner_width: num("inner_width"),
            client_width: num("client_width"),
            scroll_width: num("scroll_width"),
            graphs: v["graphs"].as_u64().unwrap_or(0),
            texts: v["texts"].as_u64().unwrap_or(0),
            smallest_px: v["smallest_px"].as_f64(),
            smallest_text: v["smallest_text"].as_str().map(str::to_string),
            scale_mismatches: v["scale_mismatches"]
                .as_array()
                .into_iter()
                .flatten()
                .map(|m| m.as_str().unwrap_or_default().to_string())
                .collect(),
        }
    }
}

/// The page's width and its graphs' smallest text, measured in the page.
/// `scope` is the CSS selector of the SVGs to measure.
const MEASURE_JS: &str = r#"
const scope = arguments[0];
const doc = document.scrollingElement;
const out = { inner_width: window.innerWidth, client_width: doc.clientWidth,
  scroll_width: doc.scrollWidth, graphs: 0, texts: 0, smallest_px: null,
  smallest_text: null, scale_mismatches: [] };
for (const svg of document.querySelectorAll(scope)) {
  out.graphs++;
  const vb = svg.viewBox.baseVal;
  const shown = svg.getBoundingClientRect().width;
  const root = svg.getScreenCTM();
  for (const t of svg.querySelectorAll('text')) {
    const m = t.getScreenCTM();
    const scale = Math.hypot(m.a, m.b);
    const px = parseFloat(getComputedStyle(t).fontSize) * scale;
    out.texts++;
    if (out.smallest_px === null || px < out.smallest_px) {
      out.smallest_px = px;
      out.smallest_text = t.textContent;
    }
  }
  // The SVG's own CTM scale is its rendered width over its viewBox width.
  if (vb && vb.width > 0) {
    const expected = shown / vb.width;
    const got = Math.hypot(root.a, root.b);
    if (Math.abs(got - expected) > 0.01 * expected) {
      out.scale_mismatches.push(svg.id + ': CTM ' + got + ' vs ' + expected);
    }
  }
}
return out;
"#;

async fn measure(c: &Client, scope: &str) -> Measure {
    let v = c
        .execute(MEASURE_JS, vec![scope.into()])
        .await
        .expect("measure the page");
    Measure::from(&v)
}

/// Open `page` of `site`, check it and keep a screenshot `name`; its path
/// is printed for a person to look at. A controller page has no graph;
/// every other page checked has at least one.
async fn look(c: &Client, site: &Path, page: &str, shots: &Path, name: &str, graphs: bool) {
    let (file, fragment) = page.split_once('#').unwrap_or((page, ""));
    let mut url = file_url(&site.join(file));
    if !fragment.is_empty() {
        url = format!("{url}#{fragment}");
    }
    c.goto(&url).await.unwrap();
    let m = measure(c, "div.graph svg").await;
    screenshot(c, shots, name).await;
    println!(
        "screenshot: {} ({page}: {} graphs, {} texts, smallest {:.1} px {:?}; page {} px in a {} px window)",
        shots.join(format!("{name}.png")).display(),
        m.graphs,
        m.texts,
        m.smallest_px.unwrap_or(f64::NAN),
        m.smallest_text.as_deref().unwrap_or(""),
        m.scroll_width,
        m.inner_width
    );
    assert_eq!(
        m.inner_width, WINDOW_WIDTH,
        "{page}: the window is not 1,400 px wide"
    );
    // No horizontal scrolling: the page is no wider than the window, nor
    // than the part of it beside the vertical scroll bar.
    assert!(
        m.scroll_width <= m.inner_width && m.scroll_width <= m.client_width,
        "{page} overflows the window: {m:?}"
    );
    assert_eq!(m.graphs > 0, graphs, "{page}: {} graphs", m.graphs);
    if let Some(smallest) = m.smallest_px {
        assert!(
            smallest >= MIN_TEXT_PX - 0.01,
            "{page}: graph text {:?} is {smallest:.2} px",
            m.smallest_text
        );
    }
    assert_eq!(m.scale_mismatches, Vec::<String>::new(), "{page}");
}

/// Every kind of page at 1,400 px: wide enough, and no small text.
#[tokio::test(flavor = "current_thread")]
async fn pages_at_1400_px_are_readable() {
    let Some((chromium, chromedriver)) = browser() else {
        return;
    };
    let dir = scratch("browser-readable", &[("valve/valve.rcs", VALVE)]);
    build_site(Path::new("plans"), &[], &dir.join("plans"));
    let finding = build_site(
        &dir.join("valve"),
        &["-W", "shadowed_row"],
        &dir.join("finding"),
    );
    assert!(
        finding["VALVE.OPEN.html"].contains("class=\"finding warning\""),
        "the plan page shows no warning"
    );
    // 60 controllers, the most the index draws whole: a hierarchy some
    // 30 nodes wide, which the page may not shrink to fit.
    super::write_set(&dir.join("sixty"), rcs_codegen::site::LARGE_SET);
    build_site(&dir.join("sixty"), &[], &dir.join("wide"));
    build_site(
        Path::new("plans/submarine"),
        &["--coverage"],
        &dir.join("coverage"),
    );
    build_site(
        Path::new("tests/data/site/new/door"),
        &["--diff", "tests/data/site/old/door"],
        &dir.join("diff"),
    );
    let shots = screenshots("readable");
    let (_driver, c) = session_sized(&chromium, &chromedriver, "1400,1000").await;
    let mut errors = Vec::new();
    for (site, page, name, graphs) in [
        ("plans", "index.html", "index", true),
        ("plans", "submarine/PR.html", "controller-PR", false),
        ("wide", "index.html", "index-wide-hierarchy", true),
        ("plans", "rcs_ex/PRIM.GOTO.html", "plan-PRIM.GOTO", true),
        ("finding", "VALVE.html", "controller-VALVE", false),
        ("finding", "VALVE.OPEN.html", "plan-with-finding", true),
        // The same page at the row with the finding, which it highlights.
        (
            "finding",
            "VALVE.OPEN.html#row-E2",
            "plan-with-finding-at-row",
            true,
        ),
        ("coverage", "PR.AHEAD.html", "coverage-PR.AHEAD", true),
        ("diff", "diff-changes.html", "changes", true),
    ] {
        look(&c, &dir.join(site), page, &shots, name, graphs).await;
        errors.extend(
            console_errors(&c)
                .await
                .into_iter()
                .map(|e| format!("{page}: {e}")),
        );
    }
    // The wide hierarchy's full-size view: natural size is wider than the
    // window; Fit shrinks it into the view.
    c.goto(&file_url(&dir.join("wide/index.html")))
        .await
        .unwrap();
    super::click(&c, "button.graph-open").await;
    assert_eq!(full_scale(&c).await.map(|s| close_to(s, 1.0)), Some(true));
    let fit = press(&c, "button.zoom-fit").await;
    assert!(fit < 0.5, "Fit left the wide hierarchy at {fit}");
    screenshot(&c, &shots, "index-wide-full-size-fit").await;
    println!(
        "screenshot: {}",
        shots.join("index-wide-full-size-fit.png").display()
    );
    errors.extend(console_errors(&c).await);

    // The finding is marked on the graph.
    c.goto(&file_url(&dir.join("finding/VALVE.OPEN.html")))
        .await
        .unwrap();
    let marked = c
        .execute(
            "return [...document.querySelectorAll('div.graph svg text')].some(t => t.textContent.includes('\u{26a0}'));",
            vec![],
        )
        .await
        .unwrap();
    assert_eq!(marked, serde_json::Value::Bool(true), "no ⚠ on the graph");
    c.close().await.unwrap();
    assert_eq!(errors, Vec::<String>::new(), "console errors");
    let _ = std::fs::remove_dir_all(&dir);
}

/// The scale the full-size view draws its graph at: rendered width over
/// natural width; `None` when the view is closed.
async fn full_scale(c: &Client) -> Option<f64> {
    let v = c
        .execute(
            "const d = document.querySelector('dialog.graph-full');
             if (!d || !d.open) { return null; }
             const svg = d.querySelector('svg');
             return svg.getBoundingClientRect().width / svg.width.baseVal.value;",
            vec![],
        )
        .await
        .unwrap();
    v.as_f64()
}

/// Where the full-size view has moved its graph: its left edge, in px.
async fn full_left(c: &Client) -> f64 {
    c.execute(
        "return document.querySelector('dialog.graph-full svg').getBoundingClientRect().left;",
        vec![],
    )
    .await
    .unwrap()
    .as_f64()
    .expect("the graph in the view")
}

fn close_to(got: f64, want: f64) -> bool {
    (got - want).abs() < 0.01 * want
}

/// Click the button `css` of the full-size view, and give the scale.
async fn press(c: &Client, css: &str) -> f64 {
    super::click(c, &format!("dialog.graph-full {css}")).await;
    full_scale(c).await.expect("the view is open")
}

/// A graph's full-size view: open, natural size, zoom, pan, Esc; a click on
/// the background opens it, and a link in it leads to its row.
#[tokio::test(flavor = "current_thread")]
async fn the_full_size_view() {
    let Some((chromium, chromedriver)) = browser() else {
        return;
    };
    let dir = scratch("browser-full-size", &[]);
    let site = dir.join("site");
    build_site(Path::new("plans/submarine"), &[], &site);
    let shots = screenshots("full-size");
    let (_driver, c) = session_sized(&chromium, &chromedriver, "1400,1000").await;
    let page = file_url(&site.join("PR.AHEAD.html"));
    c.goto(&page).await.unwrap();
    assert_eq!(full_scale(&c).await, None, "the view is open at load");

    // The button opens it: the same SVG, at natural size, its text at
    // 11 pt = 14.7 px.
    super::click(&c, "button.graph-open").await;
    assert_eq!(full_scale(&c).await.map(|s| close_to(s, 1.0)), Some(true));
    let moved = c
        .execute(
            "return document.querySelectorAll('svg').length === 1 && !document.querySelector('div.graph svg');",
            vec![],
        )
        .await
        .unwrap();
    assert_eq!(moved, serde_json::Value::Bool(true), "not the page's SVG");
    let m = measure(&c, "dialog.graph-full svg").await;
    assert!(close_to(m.smallest_px.unwrap(), 11.0 * 4.0 / 3.0), "{m:?}");
    screenshot(&c, &shots, "open").await;
    println!("screenshot: {}", shots.join("open.png").display());

    // Zoom buttons: + and − by 1.25, 1:1 back to natural size.
    assert!(close_to(press(&c, "button.zoom-in").await, 1.25));
    assert!(close_to(press(&c, "button.zoom-in").await, 1.5625));
    assert!(close_to(press(&c, "button.zoom-out").await, 1.25));
    assert!(close_to(press(&c, "button.zoom-reset").await, 1.0));
    let fit = press(&c, "button.zoom-fit").await;
    assert!(
        fit > 0.0 && !close_to(fit, 1.0),
        "Fit left the scale at {fit}"
    );
    assert!(close_to(press(&c, "button.zoom-reset").await, 1.0));

    // The wheel zooms in (scrolling up) about the pointer.
    let view = c
        .find(Locator::Css("dialog.graph-full .graph-full-view"))
        .await
        .unwrap();
    let (x, y, w, h) = view.rectangle().await.unwrap();
    let (cx, cy) = ((x + w / 2.0) as i64, (y + h / 2.0) as i64);
    let mut wheel = WheelActions::new("wheel".into());
    wheel.push(WheelAction::Scroll {
        duration: None,
        x: cx,
        y: cy,
        delta_x: 0,
        delta_y: -200,
    });
    c.perform_actions(wheel).await.unwrap();
    let zoomed = full_scale(&c).await.unwrap();
    assert!(zoomed > 1.1, "the wheel did not zoom in: {zoomed}");
    assert!(close_to(press(&c, "button.zoom-reset").await, 1.0));

    // A drag pans by as much as the pointer moved, and follows no link.
    let before = full_left(&c).await;
    let drag = MouseActions::new("mouse".into())
        .then(PointerAction::MoveTo {
            duration: None,
            x: x + 20.0,
            y: y + h - 20.0,
        })
        .then(PointerAction::Down {
            button: MOUSE_BUTTON_LEFT,
        })
        .then(PointerAction::MoveBy {
            duration: Some(Duration::from_millis(100)),
            x: 150.0,
            y: -40.0,
        })
        .then(PointerAction::Up {
            button: MOUSE_BUTTON_LEFT,
        });
    c.perform_actions(drag).await.unwrap();
    c.release_actions().await.unwrap();
    let after = full_left(&c).await;
    assert!(
        (after - before - 150.0).abs() < 2.0,
        "the drag moved the graph from {before} to {after}"
    );
    assert!(c.current_url().await.unwrap().fragment().is_none());

    // Esc closes it and puts the SVG back, shown as before.
    c.active_element()
        .await
        .unwrap()
        .send_keys(&String::from(char::from(Key::Escape)))
        .await
        .unwrap();
    assert_eq!(full_scale(&c).await, None, "Esc did not close the view");
    let back = measure(&c, "div.graph svg").await;
    assert_eq!(back.graphs, 1, "the SVG is not back in its box");
    assert!(back.smallest_px.unwrap() >= MIN_TEXT_PX - 0.01, "{back:?}");

    // A click on the graph's background (its top-left margin, where
    // Graphviz draws nothing but the white page) opens it; an edge's link
    // in the view still leads to its row, and closes the view.
    let svg = c.find(Locator::Css("div.graph svg")).await.unwrap();
    let (sx, sy, _, _) = svg.rectangle().await.unwrap();
    let background = MouseActions::new("mouse".into())
        .then(PointerAction::MoveTo {
            duration: None,
            x: sx + 6.0,
            y: sy + 6.0,
        })
        .then(PointerAction::Down {
            button: MOUSE_BUTTON_LEFT,
        })
        .then(PointerAction::Up {
            button: MOUSE_BUTTON_LEFT,
        });
    c.perform_actions(background).await.unwrap();
    c.release_actions().await.unwrap();
    assert_eq!(full_scale(&c).await.map(|s| close_to(s, 1.0)), Some(true));
    super::click(&c, "dialog.graph-full g#edge-E1 a text").await;
    assert_eq!(full_scale(&c).await, None, "the link left the view open");
    let url = c.current_url().await.unwrap();
    assert_eq!(url.fragment(), Some("row-E1"), "{url}");
    assert_eq!(super::targeted(&c).await.as_deref(), Some("row-E1"));

    let errors = console_errors(&c).await;
    c.close().await.unwrap();
    assert_eq!(errors, Vec::<String>::new(), "console errors");
    let _ = std::fs::remove_dir_all(&dir);
}

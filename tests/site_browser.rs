//! The doc site in a real browser: headless Chromium driven through
//! WebDriver (chromedriver, `fantoccini`). Build the site for `plans/`,
//! open its index, click the hierarchy's PR node, go to PR.AHEAD, click an
//! edge and land on its table row (the URL's fragment and the row the page
//! targets, highlighted); follow the row back to its edge and source line;
//! keep a screenshot of every page under `target/site-screenshots/`; no
//! page may log a console error; every link of every page resolves.
//! Also a generated set just above `LARGE_SET` (index → a cluster → a
//! controller; the search index loaded only when used) and the Changes
//! page of `rcsc doc --diff` (a changed plan's badge → its changes → back).
//!
//! And in `readable`: each kind of page at a 1,400-px window, no page
//! wider than the window and no graph text under 10 px as rendered, and
//! the full-size view of a graph (open, zoom, pan, close, follow a link).
//!
//! Chromium and chromedriver come from Debian's `chromium` and
//! `chromium-driver` packages (`.ci/run` installs them). Without them the
//! test fails and says how to install them, unless `RCSC_SKIP_BROWSER=1`.

mod common;
#[path = "../rcs-dsl/benches/common/plan_set.rs"]
mod plan_set;
#[path = "site_browser/readable.rs"]
mod readable;

use common::site_links::broken_links;
use common::{rcsc, scratch, text, tree};
use fantoccini::wd::WebDriverCompatibleCommand;
use fantoccini::{Client, ClientBuilder, Locator};
use std::net::{TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// The first of `names` found on PATH.
fn on_path(names: &[&str]) -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .flat_map(|dir| names.iter().map(move |n| dir.join(n)))
        .find(|p| p.is_file())
}

/// chromedriver, stopped when dropped.
struct Driver(Child);

impl Drop for Driver {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// Start chromedriver on a free port and wait until it listens.
fn start_driver(exe: &Path) -> (Driver, u16) {
    let port = TcpListener::bind("127.0.0.1:0")
        .and_then(|l| l.local_addr())
        .map(|a| a.port())
        .expect("a free port");
    let child = Command::new(exe)
        .arg(format!("--port={port}"))
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("chromedriver starts");
    let driver = Driver(child);
    // Readiness, not timing: a generous bound so a dead driver cannot hang the suite.
    let deadline = Instant::now() + Duration::from_secs(60);
    while TcpStream::connect(("127.0.0.1", port)).is_err() {
        assert!(
            Instant::now() < deadline,
            "chromedriver did not start listening"
        );
        std::thread::sleep(Duration::from_millis(50));
    }
    (driver, port)
}

/// chromedriver's log of the browser's console since the last call.
#[derive(Debug)]
struct BrowserLog;

impl WebDriverCompatibleCommand for BrowserLog {
    fn endpoint(
        &self,
        base: &url::Url,
        session: Option<&str>,
    ) -> Result<url::Url, url::ParseError> {
        base.join(&format!("session/{}/se/log", session.unwrap_or_default()))
    }

    fn method_and_body(&self, _: &url::Url) -> (http::Method, Option<String>) {
        (
            http::Method::POST,
            Some(r#"{"type":"browser"}"#.to_string()),
        )
    }
}

/// Console errors (level SEVERE) the browser logged since the last call.
async fn console_errors(c: &Client) -> Vec<String> {
    let log = c.issue_cmd(BrowserLog).await.expect("the browser log");
    log.as_array()
        .into_iter()
        .flatten()
        .filter(|e| e["level"] == "SEVERE")
        .map(|e| e["message"].to_string())
        .collect()
}

async fn screenshot(c: &Client, dir: &Path, name: &str) {
    let png = c.screenshot().await.expect("a screenshot");
    std::fs::write(dir.join(format!("{name}.png")), png).expect("save the screenshot");
}

/// The id of the element the page's URL fragment targets, if any.
async fn targeted(c: &Client) -> Option<String> {
    let v = c
        .execute(
            "const t = document.querySelector(':target'); return t ? t.id : null;",
            vec![],
        )
        .await
        .expect("run a script");
    v.as_str().map(str::to_string)
}

fn file_url(path: &Path) -> String {
    format!(
        "file://{}",
        path.canonicalize().expect("the site exists").display()
    )
}

/// Chromium and chromedriver, or `None` (after saying so) when they are
/// missing and `RCSC_SKIP_BROWSER=1`.
fn browser() -> Option<(PathBuf, PathBuf)> {
    let chromium = on_path(&["chromium", "chromium-browser", "google-chrome"]);
    let chromedriver = on_path(&["chromedriver"]);
    let (Some(chromium), Some(chromedriver)) = (chromium, chromedriver) else {
        if std::env::var("RCSC_SKIP_BROWSER").as_deref() == Ok("1") {
            eprintln!(
                "note: RCSC_SKIP_BROWSER=1 and Chromium is missing: the browser test did not run"
            );
            return None;
        }
        panic!(
            "the browser test needs Chromium and chromedriver: install them with \
             `apt-get install -y chromium chromium-driver` (as .ci/run does), or set \
             RCSC_SKIP_BROWSER=1 to skip this test"
        );
    };
    Some((chromium, chromedriver))
}

/// A WebDriver session with headless Chromium (and its driver, which must
/// outlive it).
async fn session(chromium: &Path, chromedriver: &Path) -> (Driver, Client) {
    session_sized(chromium, chromedriver, "1280,1000").await
}

/// A session whose window is `size` ("width,height" in CSS px).
async fn session_sized(chromium: &Path, chromedriver: &Path, size: &str) -> (Driver, Client) {
    let (driver, port) = start_driver(chromedriver);
    let caps = serde_json::json!({
        "browserName": "chrome",
        "goog:chromeOptions": {
            "binary": chromium,
            "args": ["--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage", format!("--window-size={size}")]
        },
        "goog:loggingPrefs": { "browser": "ALL" }
    });
    let serde_json::Value::Object(caps) = caps else {
        unreachable!()
    };
    let connector = hyper_util::client::legacy::connect::HttpConnector::new();
    let c = ClientBuilder::new(connector)
        .capabilities(caps)
        .connect(&format!("http://127.0.0.1:{port}/"))
        .await
        .expect("a WebDriver session");
    (driver, c)
}

/// Where the screenshots go: `target/site-screenshots/<name>/`.
fn screenshots(name: &str) -> PathBuf {
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("target"));
    let shots = target.join("site-screenshots").join(name);
    std::fs::create_dir_all(&shots).unwrap();
    shots
}

/// `rcsc doc` of `plans` (and `extra` arguments) into `site`; its files as
/// text, every link checked.
fn build_site(
    plans: &Path,
    extra: &[&str],
    site: &Path,
) -> std::collections::BTreeMap<String, String> {
    let mut args = vec!["doc", plans.to_str().unwrap(), "-o", site.to_str().unwrap()];
    args.extend(extra);
    let o = rcsc(&args);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let files: std::collections::BTreeMap<String, String> = tree(site)
        .into_iter()
        .map(|(p, b)| (p, String::from_utf8(b).unwrap()))
        .collect();
    assert_eq!(broken_links(&files), Vec::<String>::new());
    files
}

/// Visit every page: a screenshot of each, and the console errors.
async fn visit_all(
    c: &Client,
    site: &Path,
    files: &std::collections::BTreeMap<String, String>,
    shots: &Path,
) -> Vec<String> {
    let mut errors = Vec::new();
    for path in files.keys().filter(|p| p.ends_with(".html")) {
        c.goto(&file_url(&site.join(path))).await.unwrap();
        let name = path.replace('/', "__");
        screenshot(c, shots, name.trim_end_matches(".html")).await;
        errors.extend(
            console_errors(c)
                .await
                .into_iter()
                .map(|e| format!("{path}: {e}")),
        );
    }
    errors
}

#[tokio::test(flavor = "current_thread")]
async fn the_site_in_chromium() {
    let Some((chromium, chromedriver)) = browser() else {
        return;
    };
    let dir = scratch("browser", &[]);
    let site = dir.join("site");
    let files = build_site(Path::new("plans"), &[], &site);
    let shots = screenshots("plans");
    let (_driver, c) = session(&chromium, &chromedriver).await;

    // Index → the hierarchy's PR node.
    c.goto(&file_url(&site.join("index.html"))).await.unwrap();
    screenshot(&c, &shots, "index").await;
    c.find(Locator::Css("g#ctrl-PR a text"))
        .await
        .expect("PR in the hierarchy")
        .click()
        .await
        .unwrap();
    let url = c.current_url().await.unwrap();
    assert!(url.path().ends_with("/submarine/PR.html"), "{url}");
    screenshot(&c, &shots, "PR").await;

    // PR → its AHEAD plan → an edge → its table row.
    c.find(Locator::Css("tr#cmd-AHEAD a"))
        .await
        .expect("AHEAD's plan link")
        .click()
        .await
        .unwrap();
    let url = c.current_url().await.unwrap();
    assert!(url.path().ends_with("/submarine/PR.AHEAD.html"), "{url}");
    c.find(Locator::Css("g#edge-E1 a text"))
        .await
        .expect("the edge of E1")
        .click()
        .await
        .unwrap();
    let url = c.current_url().await.unwrap();
    assert_eq!(url.fragment(), Some("row-E1"), "{url}");
    assert_eq!(targeted(&c).await.as_deref(), Some("row-E1"));
    let row = c.find(Locator::Id("row-E1")).await.unwrap();
    let background = row.css_value("background-color").await.unwrap();
    // site.css: `tr:target { background: #fff2a8 }`, as rgb() or rgba().
    assert!(
        background.contains("255, 242, 168"),
        "the targeted row is not highlighted: {background}"
    );
    screenshot(&c, &shots, "PR.AHEAD-row-E1").await;

    // And back: the row's edge, then its source line.
    c.find(Locator::Css("tr#row-E1 a.to-graph"))
        .await
        .unwrap()
        .click()
        .await
        .unwrap();
    assert_eq!(targeted(&c).await.as_deref(), Some("edge-E1"));
    c.find(Locator::Css("tr#row-E1 a.to-source"))
        .await
        .unwrap()
        .click()
        .await
        .unwrap();
    let line = targeted(&c).await.expect("a source line is targeted");
    assert!(line.starts_with('L'), "{line}");
    // The source line of a row leads back to the row.
    c.find(Locator::Css(&format!("span#{line} a.ln")))
        .await
        .unwrap()
        .click()
        .await
        .unwrap();
    assert_eq!(targeted(&c).await.as_deref(), Some("row-E1"));

    // The search box finds a state and leads to it.
    c.goto(&file_url(&site.join("index.html"))).await.unwrap();
    c.find(Locator::Id("search"))
        .await
        .unwrap()
        .send_keys("PR.AHEAD.S2")
        .await
        .unwrap();
    click_once_there(&c, "#results a").await;
    let url = c.current_url().await.unwrap();
    assert!(url.path().ends_with("/submarine/PR.AHEAD.html"), "{url}");
    assert_eq!(url.fragment(), Some("state-S2"));
    let mut errors = console_errors(&c).await;

    // Every page: a screenshot, and no console error.
    errors.extend(visit_all(&c, &site, &files, &shots).await);
    c.close().await.unwrap();
    assert_eq!(errors, Vec::<String>::new(), "console errors");
    let _ = std::fs::remove_dir_all(&dir);
}

/// The `check` benchmark's generated set of `n` controllers, written to
/// `dir` (a plan set folder without a manifest: one CPU runs them all).
fn write_set(dir: &Path, n: usize) {
    std::fs::create_dir_all(dir).unwrap();
    for (path, text) in plan_set::plan_set(n) {
        std::fs::write(dir.join(path), text).unwrap();
    }
}

/// The first element `css` finds, clicked.
async fn click(c: &Client, css: &str) {
    c.find(Locator::Css(css))
        .await
        .unwrap_or_else(|e| panic!("no `{css}`: {e}"))
        .click()
        .await
        .unwrap();
}

/// The first element `css` finds once it is there, clicked: for what a
/// script puts in the page later (the search's results, after its index
/// loads). Readiness, not timing: a generous bound so that a page that
/// never shows it cannot hang the suite.
async fn click_once_there(c: &Client, css: &str) {
    c.wait()
        .at_most(Duration::from_secs(60))
        .for_element(Locator::Css(css))
        .await
        .unwrap_or_else(|e| panic!("no `{css}` within 60 s: {e}"))
        .click()
        .await
        .unwrap();
}

/// A set just above `rcs_codegen::site::LARGE_SET`: the index draws
/// clusters; a cluster leads to its controllers, a controller to its page;
/// the lists have pages; the search (loaded when first used) still finds.
#[tokio::test(flavor = "current_thread")]
async fn a_large_set_in_chromium() {
    let Some((chromium, chromedriver)) = browser() else {
        return;
    };
    let n = rcs_codegen::site::LARGE_SET + 20;
    let dir = scratch("browser-large", &[]);
    let plans = dir.join("large");
    write_set(&plans, n);
    let site = dir.join("site");
    let files = build_site(&plans, &[], &site);
    assert!(
        !files["index.html"].contains("id=\"ctrl-C0\""),
        "the whole hierarchy is drawn"
    );
    assert!(files.contains_key("list-controllers.html"));
    assert!(files.contains_key("list-buffers.html"));
    let shots = screenshots("large");
    let (_driver, c) = session(&chromium, &chromedriver).await;

    c.goto(&file_url(&site.join("index.html"))).await.unwrap();
    screenshot(&c, &shots, "index").await;
    click(&c, "g.node[id^='cluster-'] a text").await;
    let url = c.current_url().await.unwrap();
    let cluster = url.path().rsplit('/').next().unwrap().to_string();
    assert!(cluster.starts_with("cluster-"), "{url}");
    screenshot(&c, &shots, "cluster").await;
    let first = c
        .find(Locator::Css("g.node[id^='ctrl-']"))
        .await
        .expect("a controller in the cluster")
        .attr("id")
        .await
        .unwrap()
        .expect("an id");
    let name = first.trim_start_matches("ctrl-").to_string();
    click(&c, &format!("g#{first} a text")).await;
    let url = c.current_url().await.unwrap();
    assert!(url.path().ends_with(&format!("/{name}.html")), "{url}");
    let h1 = c
        .find(Locator::Css("h1"))
        .await
        .unwrap()
        .text()
        .await
        .unwrap();
    assert_eq!(h1, name);

    // The search index is not loaded until the box is used.
    let loaded = c
        .execute("return window.RCS_SEARCH !== undefined;", vec![])
        .await
        .unwrap();
    assert_eq!(loaded, serde_json::Value::Bool(false));
    c.find(Locator::Id("search"))
        .await
        .unwrap()
        .send_keys("C7.OP3")
        .await
        .unwrap();
    click_once_there(&c, "#results a").await;
    let url = c.current_url().await.unwrap();
    assert!(url.path().ends_with("/C7.OP3.html"), "{url}");
    let mut errors = console_errors(&c).await;

    // The pages the large set adds, and one controller's: plan pages are
    // as in the small set (every link of every page is checked above).
    let some: std::collections::BTreeMap<String, String> = files
        .iter()
        .filter(|(p, _)| !p.starts_with('C') || p.starts_with("C0."))
        .map(|(p, t)| (p.clone(), t.clone()))
        .collect();
    errors.extend(visit_all(&c, &site, &some, &shots).await);
    c.close().await.unwrap();
    assert_eq!(errors, Vec::<String>::new(), "console errors");
    let _ = std::fs::remove_dir_all(&dir);
}

/// `rcsc doc --diff`: a changed plan's badge leads to its part of the
/// Changes page, and that back to the plan's page.
#[tokio::test(flavor = "current_thread")]
async fn the_changes_page_in_chromium() {
    let Some((chromium, chromedriver)) = browser() else {
        return;
    };
    let dir = scratch("browser-diff", &[]);
    let site = dir.join("site");
    let files = build_site(
        Path::new("tests/data/site/new/door"),
        &["--diff", "tests/data/site/old/door"],
        &site,
    );
    let shots = screenshots("diff");
    let (_driver, c) = session(&chromium, &chromedriver).await;
    c.goto(&file_url(&site.join("DOOR.OPEN.html")))
        .await
        .unwrap();
    click(&c, "p.badge a").await;
    let url = c.current_url().await.unwrap();
    assert!(url.path().ends_with("/diff-changes.html"), "{url}");
    assert_eq!(targeted(&c).await.as_deref(), Some("plan-door.DOOR.OPEN"));
    screenshot(&c, &shots, "changes").await;
    click(&c, "div#plan-door\\.DOOR\\.OPEN h4 a").await;
    let url = c.current_url().await.unwrap();
    assert!(url.path().ends_with("/DOOR.OPEN.html"), "{url}");
    let mut errors = console_errors(&c).await;
    errors.extend(visit_all(&c, &site, &files, &shots).await);
    c.close().await.unwrap();
    assert_eq!(errors, Vec::<String>::new(), "console errors");
    let _ = std::fs::remove_dir_all(&dir);
}

/// For BENCHMARKS.md, not a check: writes the generated set of
/// `RCSC_SET_N` (default 1,000) controllers to `RCSC_SET_DIR`.
#[test]
#[ignore = "writes the benchmark's plan set; run by hand"]
fn write_the_benchmark_set() {
    let dir = std::env::var_os("RCSC_SET_DIR").expect("RCSC_SET_DIR");
    let n = std::env::var("RCSC_SET_N")
        .ok()
        .and_then(|n| n.parse().ok())
        .unwrap_or(1000);
    write_set(Path::new(&dir), n);
}

/// For BENCHMARKS.md, not a check (it asserts nothing about time): each
/// page of `RCSC_SITE_PAGES` (comma-separated, from the site
/// `RCSC_SITE_DIR`) loaded three times in headless Chromium, printing
/// `performance.timing`'s navigation start → load event end.
#[tokio::test(flavor = "current_thread")]
#[ignore = "measures page loads of a site built by hand; run by hand"]
async fn page_load_times() {
    let Some((chromium, chromedriver)) = browser() else {
        return;
    };
    let site = PathBuf::from(std::env::var_os("RCSC_SITE_DIR").expect("RCSC_SITE_DIR"));
    let pages = std::env::var("RCSC_SITE_PAGES").unwrap_or_else(|_| "index.html".into());
    let (_driver, c) = session(&chromium, &chromedriver).await;
    for page in pages.split(',') {
        let mut times = Vec::new();
        for _ in 0..3 {
            c.goto("about:blank").await.unwrap();
            c.goto(&file_url(&site.join(page))).await.unwrap();
            let ms = c
                .execute(
                    "const t = performance.timing; return t.loadEventEnd - t.navigationStart;",
                    vec![],
                )
                .await
                .unwrap();
            times.push(ms.to_string());
        }
        let bytes = std::fs::metadata(site.join(page))
            .map(|m| m.len())
            .unwrap_or(0);
        println!("{page}: {} ms ({bytes} bytes)", times.join(" / "));
    }
    c.close().await.unwrap();
}

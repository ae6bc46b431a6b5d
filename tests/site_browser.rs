//! The doc site in a real browser: headless Chromium driven through
//! WebDriver (chromedriver, `fantoccini`). Build the site for `plans/`,
//! open its index, click the hierarchy's PR node, go to PR.AHEAD, click an
//! edge and land on its table row (the URL's fragment and the row the page
//! targets, highlighted); follow the row back to its edge and source line;
//! keep a screenshot of every page under `target/site-screenshots/`; no
//! page may log a console error; every link of every page resolves.
//!
//! Chromium and chromedriver come from Debian's `chromium` and
//! `chromium-driver` packages (`.ci/run` installs them). Without them the
//! test fails and says how to install them, unless `RCSC_SKIP_BROWSER=1`.

mod common;

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

#[tokio::test(flavor = "current_thread")]
async fn the_site_in_chromium() {
    let chromium = on_path(&["chromium", "chromium-browser", "google-chrome"]);
    let chromedriver = on_path(&["chromedriver"]);
    let (Some(chromium), Some(chromedriver)) = (chromium, chromedriver) else {
        if std::env::var("RCSC_SKIP_BROWSER").as_deref() == Ok("1") {
            eprintln!(
                "note: RCSC_SKIP_BROWSER=1 and Chromium is missing: the browser test did not run"
            );
            return;
        }
        panic!(
            "the browser test needs Chromium and chromedriver: install them with \
             `apt-get install -y chromium chromium-driver` (as .ci/run does), or set \
             RCSC_SKIP_BROWSER=1 to skip this test"
        );
    };

    let dir = scratch("browser", &[]);
    let site = dir.join("site");
    let o = rcsc(&["doc", "plans", "-o", site.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let files: std::collections::BTreeMap<String, String> = tree(&site)
        .into_iter()
        .map(|(p, b)| (p, String::from_utf8(b).unwrap()))
        .collect();
    assert_eq!(broken_links(&files), Vec::<String>::new());

    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("target"));
    let shots = target.join("site-screenshots");
    std::fs::create_dir_all(&shots).unwrap();

    let (_driver, port) = start_driver(&chromedriver);
    let caps = serde_json::json!({
        "browserName": "chrome",
        "goog:chromeOptions": {
            "binary": chromium,
            "args": ["--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage", "--window-size=1280,1000"]
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
    c.find(Locator::Css("#results a"))
        .await
        .expect("a search result")
        .click()
        .await
        .unwrap();
    let url = c.current_url().await.unwrap();
    assert!(url.path().ends_with("/submarine/PR.AHEAD.html"), "{url}");
    assert_eq!(url.fragment(), Some("state-S2"));
    let mut errors = console_errors(&c).await;

    // Every page: a screenshot, and no console error.
    for path in files.keys().filter(|p| p.ends_with(".html")) {
        c.goto(&file_url(&site.join(path))).await.unwrap();
        let name = path.replace('/', "__");
        screenshot(&c, &shots, name.trim_end_matches(".html")).await;
        errors.extend(
            console_errors(&c)
                .await
                .into_iter()
                .map(|e| format!("{path}: {e}")),
        );
    }
    c.close().await.unwrap();
    assert_eq!(errors, Vec::<String>::new(), "console errors");
    let _ = std::fs::remove_dir_all(&dir);
}

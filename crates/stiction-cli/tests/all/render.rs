//! The pages as a user gets them: `stiction report` on a long record (an overview and a zoom),
//! chart text without "-0" ticks, and `stiction batch --reports`'s fleet page (sortable, a
//! verdict filter, a sparkline per loop, cards on a phone, a back link on every report), with a
//! real browser at a phone's width when one is installed.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::common;
use common::{closed_stenman, ok};

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The text of every SVG `<text>` element of the page.
fn svg_texts(html: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = html;
    while let Some(i) = rest.find("<text") {
        rest = &rest[i..];
        let Some(open_end) = rest.find('>') else {
            break;
        };
        let Some(close) = rest.find("</text>") else {
            break;
        };
        out.push(rest[open_end + 1..close].trim().to_string());
        rest = &rest[close..];
    }
    out
}

#[test]
fn a_long_record_gets_an_overview_and_a_zoom() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("long.csv");
    // 20 000 samples at 1 s: five and a half hours
    ok(&[
        "simulate",
        "--loop",
        "closed",
        "--model",
        "stenman",
        "--param",
        "d=2",
        "--samples",
        "20000",
        "--seed",
        "3",
        "-o",
        s(&csv),
    ]);
    let html_path = dir.path().join("long.html");
    let out = ok(&[
        "report",
        s(&csv),
        "--sp",
        "sp",
        "--no-quantify",
        "-o",
        s(&html_path),
    ]);
    assert!(out.contains("report written"), "{out}");
    let html = std::fs::read_to_string(&html_path).unwrap();
    for section in [
        "id=\"trends\"",
        "id=\"zoom\"",
        "id=\"phase\"",
        "id=\"indices\"",
        "id=\"oscillation\"",
        "id=\"estimates\"",
        "id=\"convergence\"",
        "id=\"quality\"",
        "id=\"notes\"",
    ] {
        assert!(html.contains(section), "{section}");
    }
    assert!(html.contains("overview of the whole record"));
    assert!(html.contains("Overview of all 20000 samples"));
    assert!(html.contains("<a href=\"#zoom\">Zoom</a>"));
    let zoom = &html[html.find("id=\"zoom\"").unwrap()..html.find("id=\"phase\"").unwrap()];
    assert!(zoom.contains("Zoom: samples "), "{}", &zoom[..300]);
    assert!(
        zoom.contains("vary most"),
        "the page says how the window was picked"
    );
    assert_eq!(
        zoom.matches("<figure>").count(),
        2,
        "PV and OP of the window"
    );
    // the overview is decimated: the page stays small for a long record
    assert!(html.len() < 3_000_000, "{} bytes", html.len());
    // tick labels: no negative zero, no ".0" on the time axis, hours for a long record
    let texts = svg_texts(&html);
    assert!(texts.iter().any(|t| t == "time (h)"), "{texts:?}");
    for t in &texts {
        assert!(t != "-0" && !t.starts_with("-0.0"), "tick {t}");
        assert!(!t.contains("tim e"), "{t}");
    }
    // a short record has no zoom
    let short = dir.path().join("short.csv");
    closed_stenman(&short, "2", &[]);
    let short_html = dir.path().join("short.html");
    ok(&[
        "report",
        s(&short),
        "--sp",
        "sp",
        "--no-quantify",
        "-o",
        s(&short_html),
    ]);
    let html = std::fs::read_to_string(&short_html).unwrap();
    assert!(!html.contains("id=\"zoom\""));
    assert!(
        !html.contains("class=\"back\""),
        "no back link outside a batch"
    );
    let texts = svg_texts(&html);
    assert!(texts.iter().any(|t| t == "time (s)"), "{texts:?}");
    // the time ticks of a 1500 s record are whole seconds, written without ".0"
    assert!(texts.iter().any(|t| t == "500" || t == "1000"), "{texts:?}");
    assert!(!texts.iter().any(|t| t.ends_with(".0")), "{texts:?}");
}

/// A plant of three loops (two sticky, one healthy) and its batch output folder.
fn fleet(dir: &Path) -> PathBuf {
    let plant = dir.join("plant");
    std::fs::create_dir_all(&plant).unwrap();
    for (name, d, seed) in [("FIC101", "2", "1"), ("LIC7", "0", "2"), ("TIC3", "3", "3")] {
        closed_stenman(
            &plant.join(format!("{name}.csv")),
            d,
            &["--noise", "0.05", "--seed", seed],
        );
    }
    let out = dir.join("out");
    ok(&[
        "batch",
        s(&plant),
        "-o",
        s(&out),
        "--sp",
        "sp",
        "--no-quantify",
        "--reports",
    ]);
    out
}

#[test]
fn the_fleet_page_sorts_filters_and_shows_sparklines() {
    let dir = tempfile::tempdir().unwrap();
    let out = fleet(dir.path());
    let index = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(index.starts_with("<!DOCTYPE html>"));
    assert!(index.contains("name=\"viewport\""));
    // the table, one row per loop, each with its report and a sparkline of PV and OP
    assert_eq!(index.matches("<tr data-verdict=").count(), 3);
    assert_eq!(index.matches("<svg class=\"spark\"").count(), 3);
    assert_eq!(index.matches("<polyline class=\"pv\"").count(), 3);
    assert_eq!(index.matches("<polyline class=\"op\"").count(), 3);
    for name in ["FIC101", "LIC7", "TIC3"] {
        assert!(
            index.contains(&format!("href=\"reports/{name}.html\"")),
            "{name}"
        );
    }
    // a sparkline has at most 100 points a series
    let first = &index[index.find("<polyline class=\"pv\" points=\"").unwrap() + 29..];
    let points = &first[..first.find('"').unwrap()];
    let n = points.split(' ').count();
    assert!((50..=100).contains(&n), "{n} points");
    // sortable columns and a verdict filter, by inline script only
    assert_eq!(index.matches("<script").count(), 1);
    assert!(!index.contains("<script src"));
    assert!(index.contains("addEventListener(\"click\""));
    assert!(index.contains("aria-sort"));
    assert!(index.contains("<select id=\"verdict-filter\">"));
    assert!(index.contains("<option value=\"stiction\">stiction (2)</option>"));
    assert!(index.contains("data-key="));
    // the band in % of span; cards on a phone
    assert!(index.contains("Band (% of span)"));
    // what a loop not called sticky may still hide: its cell carries a band, a sticky one's none
    assert!(index.contains("Hidden under (% of span)"));
    let hidden: Vec<&str> = index
        .split("data-label=\"Hidden under (% of span)\" data-key=\"")
        .skip(1)
        .map(|c| &c[..c.find('"').unwrap()])
        .collect();
    assert_eq!(hidden.len(), 3);
    assert_eq!(
        hidden.iter().filter(|k| k.is_empty()).count(),
        2,
        "{hidden:?}"
    );
    assert!(hidden
        .iter()
        .any(|k| k.parse::<f64>().is_ok_and(|b| b > 0.0)));
    assert!(index.contains("@media (max-width: 600px)"));
    assert!(index.contains("data-label=\"Verdict\""));
    // one stylesheet with the reports
    let report = std::fs::read_to_string(out.join("reports/FIC101.html")).unwrap();
    assert!(report.contains("@media (max-width: 600px)"));
    // the back link, rendered by the page's template above the header
    let main = report.find("<main").unwrap();
    let back = report
        .find("<p class=\"back\"><a href=\"../index.html\">&larr; all loops</a></p>")
        .expect("the back link");
    let header = report.find("<header>").unwrap();
    assert!(main < back && back < header);
    assert_eq!(report.matches("class=\"back\"").count(), 1);
    assert!(!report.contains("<script"), "a report has no script");
    // --resume keeps every loop and still shows its sparkline (the loop is read again)
    let plant = dir.path().join("plant");
    let again = ok(&[
        "batch",
        s(&plant),
        "-o",
        s(&out),
        "--sp",
        "sp",
        "--no-quantify",
        "--reports",
        "--resume",
    ]);
    assert!(again.contains("3 kept"), "{again}");
    let index = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert_eq!(index.matches("<svg class=\"spark\"").count(), 3);
}

// ---------------------------------------------------------------------------------------------
// A real browser: headless Chromium at a phone's width

fn find_browser() -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    [
        "chromium",
        "chromium-browser",
        "google-chrome",
        "google-chrome-stable",
    ]
    .into_iter()
    .find_map(|name| {
        std::env::split_paths(&path)
            .map(|d| d.join(name))
            .find(|p| p.is_file())
    })
}

/// Run `cmd`, killing it after `limit`: its stdout, or `None` when it failed or ran out of time.
fn output_with_limit(cmd: &mut Command, limit: Duration) -> Option<String> {
    let mut child = cmd
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .ok()?;
    let mut stdout = child.stdout.take()?;
    let reader = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = std::io::Read::read_to_string(&mut stdout, &mut s);
        s
    });
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().ok()? {
            let text = reader.join().ok()?;
            return status.success().then_some(text);
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            return None;
        }
        std::thread::sleep(Duration::from_millis(100));
    }
}

fn chromium(browser: &Path, profile: &Path, extra: &[&str]) -> Command {
    let mut cmd = Command::new(browser);
    cmd.args([
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-dev-shm-usage",
        "--no-first-run",
        "--hide-scrollbars",
        &format!("--user-data-dir={}", s(profile)),
    ])
    .args(extra);
    cmd
}

/// Share of pixels that are not (near) white, and the image size.
fn ink(png_path: &Path) -> (f64, (u32, u32)) {
    let mut decoder = png::Decoder::new(std::fs::File::open(png_path).unwrap());
    decoder.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    let channels = info.line_size / info.width as usize;
    let (mut inked, mut total) = (0usize, 0usize);
    for row in buf[..info.buffer_size()].chunks(info.line_size) {
        for px in row.chunks(channels).take(info.width as usize) {
            total += 1;
            if px.iter().take(3.min(channels)).any(|&c| c < 200) {
                inked += 1;
            }
        }
    }
    (inked as f64 / total as f64, (info.width, info.height))
}

#[test]
fn the_fleet_page_fits_a_phone_in_headless_chromium() {
    let Some(browser) = find_browser() else {
        println!("skipped: no chromium on PATH (install it, e.g. apt-get install chromium)");
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let out = fleet(dir.path());
    // the page in a 390 px frame (a headless window is at least 500 px wide); once loaded, the
    // frame's document writes its layout width into the DOM, then the script sorts by loop name
    // and filters to one verdict, and the probe writes what the table shows
    let probe = r#"<!DOCTYPE html><html><body style="margin:0">
<iframe src="index.html" style="width:390px;height:900px;border:0" onload="
var d = this.contentDocument, e = d.documentElement, b = document.body;
b.setAttribute('data-scroll-width', e.scrollWidth);
b.setAttribute('data-client-width', e.clientWidth);
d.querySelectorAll('thead th button')[1].click();
var rows = d.getElementById('fleet').tBodies[0].rows;
b.setAttribute('data-first', rows[0].dataset.verdict + ':' + rows[0].cells[1].dataset.key);
var f = d.getElementById('verdict-filter');
f.value = 'no_stiction';
f.dispatchEvent(new Event('change'));
var shown = 0;
for (var i = 0; i < rows.length; i++) { if (!rows[i].hidden) shown++; }
b.setAttribute('data-shown', shown);
"></iframe></body></html>"#;
    let probe_path = out.join("probe.html");
    std::fs::write(&probe_path, probe).unwrap();
    let url = format!("file://{}", s(&probe_path));
    let dom = output_with_limit(
        &mut chromium(
            &browser,
            &dir.path().join("p1"),
            &[
                "--allow-file-access-from-files",
                "--window-size=800,1000",
                "--dump-dom",
                &url,
            ],
        ),
        Duration::from_secs(120),
    )
    .unwrap_or_else(|| panic!("{}: --dump-dom failed", browser.display()));
    let attr = |name: &str| -> u32 {
        let key = format!("{name}=\"");
        let at = dom
            .find(&key)
            .unwrap_or_else(|| panic!("{name} not in the DOM"))
            + key.len();
        dom[at..at + dom[at..].find('"').unwrap()].parse().unwrap()
    };
    let (scroll, client) = (attr("data-scroll-width"), attr("data-client-width"));
    println!("phone: scrollWidth {scroll}, clientWidth {client}");
    assert!(client <= 390, "the viewport is {client} px wide");
    assert!(
        scroll <= client,
        "the page is {scroll} px wide in a {client} px viewport"
    );
    // and it is not blank
    let shot = dir.path().join("phone.png");
    let url = format!("file://{}", s(&out.join("index.html")));
    let done = output_with_limit(
        &mut chromium(
            &browser,
            &dir.path().join("p2"),
            &[
                "--window-size=390,900",
                &format!("--screenshot={}", s(&shot)),
                &url,
            ],
        ),
        Duration::from_secs(120),
    );
    assert!(done.is_some() && shot.exists(), "no screenshot");
    let (inked, (w, _)) = ink(&shot);
    println!("phone: {w} px wide, {inked:.4} of the pixels inked");
    assert_eq!(w, 390);
    assert!(inked > 0.02, "the page looks blank ({inked:.4})");
    if let Ok(keep) = std::env::var("STICTION_REPORT_PNG_DIR") {
        let _ = std::fs::copy(&shot, Path::new(&keep).join("fleet-phone.png"));
    }
}

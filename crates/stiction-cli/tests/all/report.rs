//! `stiction report`: the page is self-contained (no network reference of any kind), escapes the
//! data's text, and renders in a real browser (headless Chromium) on a laptop and a phone width.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::common;
use common::{closed_stenman, ok, stiction};

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// A closed loop with a sticky valve (Stenman d = 2): the report says stiction.
fn sticky_loop(dir: &Path) -> PathBuf {
    let csv = dir.join("loop.csv");
    closed_stenman(&csv, "2", &[]);
    csv
}

/// Every reference out of the file: attribute values of src/href/xlink:href/action/poster,
/// CSS url(...) and @import. Only in-page fragments (#id) and data: URLs are allowed.
fn external_references(html: &str) -> Vec<String> {
    let lower = html.to_ascii_lowercase();
    let mut bad = Vec::new();
    for needle in [
        "http://", "https://", "@import", "<link", "<script", "<iframe", "<img",
    ] {
        if lower.contains(needle) {
            bad.push(format!("contains {needle}"));
        }
    }
    let allowed = |v: &str| {
        let v = v.trim_start_matches(['"', '\'', ' ']);
        v.starts_with('#') || v.starts_with("data:")
    };
    for attr in [
        " src=", " href=", ":href=", " action=", " poster=", " srcset=",
    ] {
        for (i, _) in lower.match_indices(attr) {
            let value = &lower[i + attr.len()..];
            if !allowed(value) {
                bad.push(format!("{attr}{}", &value[..value.len().min(40)]));
            }
        }
    }
    for (i, _) in lower.match_indices("url(") {
        let value = &lower[i + 4..];
        if !allowed(value) {
            bad.push(format!("url({}", &value[..value.len().min(40)]));
        }
    }
    if lower.contains("src=\"//") || lower.contains("href=\"//") {
        bad.push("protocol-relative reference".into());
    }
    bad
}

#[test]
fn report_of_a_sticky_loop_is_self_contained() {
    let dir = tempfile::tempdir().unwrap();
    let csv = sticky_loop(dir.path());
    let html_path = dir.path().join("r.html");
    let out = ok(&["report", s(&csv), "--sp", "sp", "-o", s(&html_path)]);
    assert!(out.contains("stiction"), "{out}");
    assert!(out.contains("r.html"), "{out}");
    let html = std::fs::read_to_string(&html_path).unwrap();

    assert!(html.starts_with("<!DOCTYPE html>"));
    assert!(
        html.contains("loop.csv: stiction</h1>"),
        "title with the verdict"
    );
    assert!(html.contains("class=\"verdict v-stiction\""));
    // first the verdict and P, the reasons, the band and the next step; the families folded below
    assert!(html.contains("P(sticky valve) "));
    let at = |needle: &str| {
        html.find(needle)
            .unwrap_or_else(|| panic!("{needle} not in the page"))
    };
    let (why, band, next, trends, folded) = (
        at("<ul class=\"reasons\">"),
        at("Stiction band: "),
        at("<strong>Next step:</strong> "),
        at("id=\"trends\""),
        at("<details class=\"family\">"),
    );
    assert!(why < band && band < next && next < trends && trends < folded);
    let reasons = &html[why..html[why..].find("</ul>").unwrap() + why];
    assert!(reasons.matches("<li>").count() >= 1, "{reasons}");
    assert!(!html.contains("statistics combined") && !html.contains("trained trees"));
    for name in ["cross_correlation", "curve_fitting", "shape"] {
        assert!(html.contains(&format!("<code>{name}</code>")), "{name}");
    }
    for section in [
        "id=\"trends\"",
        "id=\"phase\"",
        "id=\"evidence\"",
        "id=\"indices\"",
        "id=\"oscillation\"",
        "id=\"estimates\"",
        "id=\"convergence\"",
        "id=\"quality\"",
        "id=\"notes\"",
    ] {
        assert!(html.contains(section), "{section}");
    }
    // the estimate, the model overlay, the estimator and the caveat
    assert!(html.contains("Stiction band"));
    assert!(html.contains("Closed-loop fit with and without stiction"));
    assert!(html.contains("<th>Log-odds</th>"), "the model's reading");
    for family in ["closed-loop fit", "stick-slip episodes", "linear loop"] {
        assert!(
            html.contains(&format!("<span class=\"family-name\">{family}</span>")),
            "{family}"
        );
    }
    // on a phone each row of a wide table is a card, each cell named by its column
    assert!(html.contains("<td class=\"text\" data-label=\"Threshold\">"));
    assert!(html.contains("table.wide td::before { content: attr(data-label)"));
    assert!(html.contains("% of valve span</strong>"));
    assert!(html.contains("Valve position at the first sample"));
    assert!(html.contains("optimal set"));
    assert!(html.contains("estimated MV"));
    assert!(html.contains("PV simulated"));
    // the phase plot's band in the verdict's units
    let label = html
        .split("Stenman d = ")
        .nth(1)
        .expect("the phase plot names the fitted model");
    assert!(label.starts_with(char::is_numeric), "{}", &label[..40]);
    assert!(
        label.split(',').next().unwrap().ends_with(" % of span"),
        "{}",
        &label[..40]
    );
    assert!(html.contains("Distinct valve trajectories (cells)"));
    assert!(html.contains("proven over every distinct valve trajectory"));
    assert!(html.contains("each cell of the whole record lies inside"));
    assert!(html.contains("without the valve position"));
    assert!(html.contains("<code>record_length</code>"));

    let svgs = html.matches("<svg").count();
    assert!(svgs >= 2, "{svgs} inline SVGs");
    assert!(html.matches("viewBox=\"0 0 ").count() >= svgs);
    assert!(!html.contains("<?xml"), "XML declaration left in the page");
    assert!(html.contains("@media print"));
    assert!(html.contains("name=\"viewport\""));
    let bad = external_references(&html);
    assert!(bad.is_empty(), "external references: {bad:?}");
    // written atomically: no temporary file left beside it
    let left: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| n.contains(".tmp"))
        .collect();
    assert!(left.is_empty(), "{left:?}");
}

#[test]
fn report_escapes_file_and_column_names_and_shows_windows() {
    let dir = tempfile::tempdir().unwrap();
    let csv = sticky_loop(dir.path());
    // a setpoint column and a file name that are HTML
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().replace("sp", "s<i>&x");
    let odd = dir.path().join("a<b>&'c.csv");
    let body: Vec<&str> = lines.collect();
    std::fs::write(&odd, format!("{header}\n{}\n", body.join("\n"))).unwrap();
    let html_path = dir.path().join("w.html");
    ok(&[
        "report",
        s(&odd),
        "--sp",
        "s<i>&x",
        "--window",
        "500",
        "--no-quantify",
        "-o",
        s(&html_path),
    ]);
    let html = std::fs::read_to_string(&html_path).unwrap();
    assert!(!html.contains("a<b>"), "file name not escaped");
    assert!(html.contains("a&lt;b&gt;&amp;&#39;c.csv"));
    assert!(!html.contains("s<i>&x"), "column name not escaped");
    assert!(html.contains("s&lt;i&gt;&amp;x"));
    assert!(html.contains("id=\"windows\""));
    assert_eq!(html.matches("<title>samples ").count(), 3, "one per window");
    assert!(html.contains("<code>--no-quantify</code>"));
    assert!(!html.contains("estimated MV"));
    assert!(external_references(&html).is_empty());
}

#[test]
fn report_says_how_the_record_was_read() {
    // a unit after every number: dropped by the reader, and the page says so beside the
    // diagnosis' own notes
    let dir = tempfile::tempdir().unwrap();
    let csv = sticky_loop(dir.path());
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    let mut out = format!("{}\n", lines.next().unwrap());
    for l in lines {
        out.push_str(&format!("{l} m3/h\n"));
    }
    let p = dir.path().join("units.csv");
    std::fs::write(&p, out).unwrap();
    let html = dir.path().join("r.html");
    ok(&["report", s(&p), "--no-quantify", "-o", s(&html)]);
    let page = std::fs::read_to_string(&html).unwrap();
    assert!(
        page.contains("How the record was read:"),
        "no reading notes"
    );
    assert!(
        page.contains("&#39;m3/h&#39; after every number of column &#39;pv&#39;"),
        "the unit note is missing"
    );
}

#[test]
fn missing_column_is_one_line_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let csv = sticky_loop(dir.path());
    let html_path = dir.path().join("r.html");
    let out = stiction(&["report", s(&csv), "--sp", "setpoint", "-o", s(&html_path)]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.trim().lines().count(), 1, "not one line: {err}");
    assert!(err.contains("'setpoint'"), "{err}");
    assert!(err.contains("--sp"), "{err}");
    assert!(!html_path.exists(), "no report for a failed run");
}

// ---------------------------------------------------------------------------------------------
// A real browser

fn on_path(name: &str) -> Option<PathBuf> {
    std::env::split_paths(&std::env::var_os("PATH")?)
        .map(|d| d.join(name))
        .find(|p| p.is_file())
}

fn find_browser() -> Option<PathBuf> {
    [
        "chromium",
        "chromium-browser",
        "google-chrome",
        "google-chrome-stable",
    ]
    .into_iter()
    .find_map(on_path)
}

/// Run `cmd`, killing it after `limit`; `None` when it could not start or ran out of time.
fn run_with_limit(cmd: &mut Command, limit: Duration) -> Option<bool> {
    let mut child = cmd
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .ok()?;
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().ok()? {
            return Some(status.success());
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            return None;
        }
        std::thread::sleep(Duration::from_millis(100));
    }
}

fn is_root() -> bool {
    Command::new("id")
        .arg("-u")
        .output()
        .map(|o| String::from_utf8_lossy(&o.stdout).trim() == "0")
        .unwrap_or(false)
}

/// Chromium on PATH, else installed with apt-get when running as root; the reason otherwise.
fn browser() -> Result<PathBuf, String> {
    if let Some(b) = find_browser() {
        return Ok(b);
    }
    if !is_root() {
        return Err("not on PATH and not root, so not installed".into());
    }
    if on_path("apt-get").is_none() {
        return Err("not on PATH and no apt-get to install it".into());
    }
    let apt = |args: &[&str]| {
        run_with_limit(
            Command::new("apt-get")
                .args(args)
                .env("DEBIAN_FRONTEND", "noninteractive"),
            Duration::from_secs(180),
        )
    };
    eprintln!("report test: installing chromium with apt-get (up to a few minutes)");
    if apt(&["install", "-y", "-q", "chromium"]) != Some(true) {
        // the package lists may be missing in a fresh container
        let _ = apt(&["update", "-q"]);
        let _ = apt(&["install", "-y", "-q", "chromium"]);
    }
    find_browser().ok_or_else(|| "apt-get install -y chromium did not provide it".into())
}

/// Share of pixels that are ink (text, lines) and of clearly coloured pixels (plot lines, chips).
fn ink_and_colour(png_path: &Path) -> (f64, f64, (u32, u32)) {
    let file = std::fs::File::open(png_path).unwrap();
    let mut decoder = png::Decoder::new(file);
    decoder.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    let channels = match info.color_type {
        png::ColorType::Rgba => 4,
        png::ColorType::Rgb => 3,
        png::ColorType::GrayscaleAlpha => 2,
        _ => 1,
    };
    let (mut ink, mut colour, mut total) = (0usize, 0usize, 0usize);
    for row in buf[..info.buffer_size()].chunks(info.line_size) {
        for px in row.chunks(channels).take(info.width as usize) {
            let rgb = if channels >= 3 {
                [px[0], px[1], px[2]]
            } else {
                [px[0]; 3]
            };
            let (lo, hi) = (*rgb.iter().min().unwrap(), *rgb.iter().max().unwrap());
            total += 1;
            if lo < 160 {
                ink += 1;
            }
            if hi - lo > 80 {
                colour += 1;
            }
        }
    }
    (
        ink as f64 / total as f64,
        colour as f64 / total as f64,
        (info.width, info.height),
    )
}

#[test]
fn report_renders_in_headless_chromium() {
    let browser = match browser() {
        Ok(b) => b,
        Err(why) => {
            println!("skipped: no chromium ({why})");
            return;
        }
    };
    let dir = tempfile::tempdir().unwrap();
    let csv = sticky_loop(dir.path());
    let html_path = dir.path().join("r.html");
    ok(&["report", s(&csv), "--sp", "sp", "-o", s(&html_path)]);
    let url = format!("file://{}", s(&html_path));
    for (name, size) in [("laptop", "1280,2000"), ("phone", "390,1600")] {
        let shot = dir.path().join(format!("{name}.png"));
        let profile = dir.path().join(format!("profile-{name}"));
        let finished = run_with_limit(
            Command::new(&browser).args([
                "--headless",
                "--no-sandbox",
                "--disable-gpu",
                "--disable-dev-shm-usage",
                "--no-first-run",
                "--hide-scrollbars",
                &format!("--user-data-dir={}", s(&profile)),
                &format!("--screenshot={}", s(&shot)),
                &format!("--window-size={size}"),
                &url,
            ]),
            Duration::from_secs(120),
        );
        if finished.is_none() || !shot.exists() {
            // a browser that is there must render: only its absence skips
            panic!("{}: no screenshot at {name} width", browser.display());
        }
        let (ink, colour, (w, h)) = ink_and_colour(&shot);
        println!("{name}: {w}x{h}, ink {ink:.4}, colour {colour:.4}");
        let want_w: u32 = size.split(',').next().unwrap().parse().unwrap();
        assert_eq!(w, want_w, "{name}: screenshot width");
        assert!(ink > 0.01, "{name}: the page looks blank (ink {ink:.4})");
        assert!(
            colour > 0.005,
            "{name}: no coloured pixels: the charts or the verdict box did not render ({colour:.4})"
        );
        if let Ok(keep) = std::env::var("STICTION_REPORT_PNG_DIR") {
            let _ = std::fs::copy(&shot, Path::new(&keep).join(format!("report-{name}.png")));
        }
    }
}

//! `stiction batch` against the faults plants meet every week: two runs into one folder, an
//! input replaced between a run and `--resume`, a scheduler's SIGTERM or a Ctrl-C, a full disk,
//! and `kill -9` at any moment. Each drives the binary as a user would.
//!
//! Two test hooks of debug builds (the test binary's; a release build ignores them) make these
//! deterministic: `STICTION_TEST_GATE=FILE` holds every worker after its loop until FILE exists
//! (so a signal or a second run surely meets a running batch), and `STICTION_TEST_FAIL_WRITE=N`
//! makes the Nth file write and every later one fail with "no space left on device".

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

use crate::common;
use common::closed_stenman;

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The test hooks exist in debug builds only (`cargo test`); under `cargo test --release` the
/// tests that need them say so and pass without running.
fn hooks() -> bool {
    if !cfg!(debug_assertions) {
        eprintln!("skipped: the batch's test hooks exist in debug builds only; run `cargo test` without --release");
    }
    cfg!(debug_assertions)
}

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_stiction"))
}

/// A folder of `n` small loops, sticky and healthy in turn, each with its own noise.
fn plant(dir: &Path, n: usize) -> PathBuf {
    let plant = dir.join("plant");
    std::fs::create_dir_all(&plant).unwrap();
    for k in 0..n {
        let d = if k % 2 == 0 { "2" } else { "0" };
        let seed = (k + 1).to_string();
        closed_stenman(
            &plant.join(format!("loop{k:02}.csv")),
            d,
            &["--noise", "0.05", "--seed", &seed],
        );
    }
    plant
}

fn batch_args<'a>(plant: &'a Path, out: &'a Path, extra: &[&'a str]) -> Vec<&'a str> {
    let mut v = vec![
        "batch",
        s(plant),
        "-o",
        s(out),
        "--sp",
        "sp",
        "--no-quantify",
    ];
    v.extend_from_slice(extra);
    v
}

fn run(args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut c = bin();
    c.args(args);
    for (k, v) in env {
        c.env(k, v);
    }
    c.output().expect("the binary runs")
}

fn spawn(args: &[&str], env: &[(&str, &str)]) -> Child {
    let mut c = bin();
    c.args(args).stdout(Stdio::piped()).stderr(Stdio::piped());
    for (k, v) in env {
        c.env(k, v);
    }
    c.spawn().expect("the binary starts")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Wait (polling) until `cond` holds; a test that waits a minute has failed.
fn wait_for(what: &str, mut cond: impl FnMut() -> bool) {
    let start = Instant::now();
    while !cond() {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "gave up waiting for {what}"
        );
        std::thread::sleep(Duration::from_millis(5));
    }
}

/// Wait for a child to end by itself; kill it and fail after a minute.
fn finish(mut child: Child, what: &str) -> Output {
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > Duration::from_secs(60) {
            let _ = child.kill();
            panic!("{what}: still running after a minute");
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    child.wait_with_output().unwrap()
}

/// A running batch whose stderr is read as it comes.
struct Watched {
    child: Child,
    err: std::sync::Arc<std::sync::Mutex<String>>,
    reader: std::thread::JoinHandle<()>,
}

fn watch(args: &[&str], env: &[(&str, &str)]) -> Watched {
    use std::io::BufRead;
    let mut child = spawn(args, env);
    let pipe = child.stderr.take().unwrap();
    let err = std::sync::Arc::new(std::sync::Mutex::new(String::new()));
    let sink = std::sync::Arc::clone(&err);
    let reader = std::thread::spawn(move || {
        for line in std::io::BufReader::new(pipe).lines() {
            let line = line.unwrap();
            let mut e = sink.lock().unwrap();
            e.push_str(&line);
            e.push('\n');
        }
    });
    Watched { child, err, reader }
}

impl Watched {
    fn said(&self, needle: &str) -> bool {
        self.err.lock().unwrap().contains(needle)
    }

    /// Wait for the end; the exit code and everything said on stderr.
    fn finish(self, what: &str) -> (Option<i32>, String) {
        let o = finish(self.child, what);
        self.reader.join().unwrap();
        let err = self.err.lock().unwrap().clone();
        (o.status.code(), err)
    }
}

fn json_files(dir: &Path) -> usize {
    std::fs::read_dir(dir).map_or(0, |d| {
        d.filter(|e| {
            let name = e.as_ref().unwrap().file_name();
            let name = name.to_string_lossy();
            name.ends_with(".json") && !name.starts_with('.')
        })
        .count()
    })
}

fn signal(child: &Child, sig: &str) {
    let ok = Command::new("kill")
        .args([sig, &child.id().to_string()])
        .status()
        .unwrap()
        .success();
    assert!(ok, "kill {sig}");
}

/// summary.csv as rows of column name -> cell, without the timing column.
fn summary(out: &Path) -> Vec<BTreeMap<String, String>> {
    let mut r = csv::Reader::from_path(out.join("summary.csv")).unwrap();
    let headers = r.headers().unwrap().clone();
    r.records()
        .map(|rec| {
            let mut row: BTreeMap<String, String> = headers
                .iter()
                .zip(rec.unwrap().iter())
                .map(|(h, c)| (h.to_string(), c.to_string()))
                .collect();
            row.remove("seconds");
            row
        })
        .collect()
}

/// Every temporary file under `dir`.
fn temps(dir: &Path) -> Vec<PathBuf> {
    let mut found = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            if p.is_dir() {
                stack.push(p);
            } else if name.contains("stiction-tmp") || name.contains(".tmp") {
                found.push(p);
            }
        }
    }
    found
}

#[test]
fn a_second_run_into_a_busy_folder_stops_at_once_naming_the_first() {
    if !hooks() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let plant = plant(dir.path(), 4);
    let out = dir.path().join("out");
    let gate = dir.path().join("gate");
    let first = spawn(
        &batch_args(&plant, &out, &["--threads", "1"]),
        &[("STICTION_TEST_GATE", s(&gate))],
    );
    wait_for("the first loop file", || json_files(&out.join("loops")) > 0);
    // the first run is held after its first loop: a second run meets it for sure
    let before = std::fs::read(out.join("summary.csv")).unwrap();
    let second = run(&batch_args(&plant, &out, &[]), &[]);
    let err = stderr(&second);
    assert_eq!(second.status.code(), Some(2), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    for needle in [
        s(&out),
        "another stiction batch is writing into this folder",
        &format!("pid {}", first.id()),
        "started 20",
        "wait for it to finish, or choose another folder with -o OUTDIR",
    ] {
        assert!(err.contains(needle), "'{needle}' missing: {err}");
    }
    // it wrote nothing
    assert_eq!(std::fs::read(out.join("summary.csv")).unwrap(), before);
    std::fs::write(&gate, "").unwrap();
    let first = finish(first, "the first run");
    assert_eq!(first.status.code(), Some(0), "{}", stderr(&first));
    assert_eq!(summary(&out).len(), 4);
    // a killed run's lock goes with its process: the next run takes the folder
    std::fs::remove_file(&gate).unwrap();
    let mut held = spawn(
        &batch_args(&plant, &out, &["--threads", "1"]),
        &[("STICTION_TEST_GATE", s(&gate))],
    );
    let loops = out.join("loops");
    let old = std::fs::metadata(loops.join("loop00.json"))
        .unwrap()
        .modified()
        .unwrap();
    wait_for("the held run's first loop", || {
        std::fs::metadata(loops.join("loop00.json")).is_ok_and(|m| m.modified().unwrap() != old)
    });
    held.kill().unwrap();
    held.wait().unwrap();
    let again = run(&batch_args(&plant, &out, &["--resume"]), &[]);
    assert_eq!(again.status.code(), Some(0), "{}", stderr(&again));
}

#[test]
fn resume_diagnoses_a_changed_input_again_and_marks_a_vanished_one() {
    let dir = tempfile::tempdir().unwrap();
    let plant = plant(dir.path(), 3);
    let out = dir.path().join("out");
    let o = run(&batch_args(&plant, &out, &[]), &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let before = summary(&out);
    let verdict = |rows: &[BTreeMap<String, String>], id: &str| {
        rows.iter().find(|r| r["loop_id"] == id).unwrap()["verdict"].clone()
    };
    assert_eq!(verdict(&before, "loop00"), "stiction");
    let kept_time = |name: &str| {
        std::fs::metadata(out.join("loops").join(name))
            .unwrap()
            .modified()
            .unwrap()
    };
    let loop01 = kept_time("loop01.json");
    // a new export of loop00 (now a healthy valve) under the same name; loop02 is gone; loop01
    // is rewritten unchanged (a copy: new time, same bytes); a new loop arrives
    closed_stenman(
        &plant.join("loop00.csv"),
        "0",
        &["--noise", "0.05", "--seed", "77"],
    );
    std::fs::remove_file(plant.join("loop02.csv")).unwrap();
    let bytes = std::fs::read(plant.join("loop01.csv")).unwrap();
    std::fs::write(plant.join("loop01.csv"), bytes).unwrap();
    closed_stenman(&plant.join("loop03.csv"), "0", &["--seed", "5"]);
    let o = run(&batch_args(&plant, &out, &["--resume"]), &[]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        text.contains(
            "resume: 1 kept, 1 redone because their input or settings changed, 1 new, 1 kept whose input is gone (source_status vanished)"
        ),
        "{text}"
    );
    let after = summary(&out);
    assert_eq!(after.len(), 4);
    assert_eq!(verdict(&after, "loop00"), "no_stiction");
    assert_eq!(
        kept_time("loop01.json"),
        loop01,
        "loop01 was diagnosed again"
    );
    let gone = after.iter().find(|r| r["loop_id"] == "loop02").unwrap();
    assert_eq!(gone["source_status"], "vanished");
    assert!(gone["source"].ends_with("loop02.csv"), "{gone:?}");
    for r in after.iter().filter(|r| r["loop_id"] != "loop02") {
        assert_eq!(r["source_status"], "present", "{r:?}");
    }
    // the loop's JSON says where it came from
    let j: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("loops/loop00.json")).unwrap()).unwrap();
    let input = &j["input"];
    assert!(input["path"].as_str().unwrap().ends_with("loop00.csv"));
    let size = std::fs::metadata(plant.join("loop00.csv")).unwrap().len();
    assert_eq!(input["size"].as_u64(), Some(size));
    assert_eq!(input["hash"].as_str().unwrap().len(), 16);
    assert!(input["modified"].as_str().unwrap().starts_with("20"));
    assert_eq!(j["verdict"], "no_stiction");
}

/// A batch held after its first loop gets `sig`: it stops handing out loops, writes the summary
/// of what is done and exits `code`; `--resume` then finishes to the undisturbed summary.
fn stop_with(sig: &str, code: i32) {
    if !hooks() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let plant = plant(dir.path(), 6);
    let reference = dir.path().join("reference");
    let o = run(&batch_args(&plant, &reference, &["--reports"]), &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = dir.path().join("out");
    let gate = dir.path().join("gate");
    let child = watch(
        &batch_args(&plant, &out, &["--threads", "1", "--reports"]),
        &[("STICTION_TEST_GATE", s(&gate))],
    );
    wait_for("the first loop file", || json_files(&out.join("loops")) > 0);
    signal(&child.child, sig);
    // the batch says it is stopping before the held loop is let go
    wait_for("the stopping message", || child.said("batch: stopping"));
    assert!(child.said("a second Ctrl-C stops at once"));
    std::fs::write(&gate, "").unwrap();
    let (status, err) = child.finish("the signalled run");
    assert_eq!(status, Some(code), "{err}");
    assert!(
        err.contains("stopped after 1 of 6 loops; run the same command with --resume to finish"),
        "{err}"
    );
    // the summary shows the work that was done
    let rows = summary(&out);
    assert_eq!(rows.len(), 1, "{rows:?}");
    assert_eq!(json_files(&out.join("loops")), 1);
    let j: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(j["complete"], false);
    assert!(std::fs::read_to_string(out.join("index.html"))
        .unwrap()
        .contains("interrupted"));
    let o = run(&batch_args(&plant, &out, &["--reports", "--resume"]), &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("resume: 1 kept, 0 redone"));
    assert_eq!(summary(&out), summary(&reference));
    assert!(temps(&out).is_empty(), "{:?}", temps(&out));
}

#[test]
fn sigterm_stops_cleanly_with_143_and_resume_finishes() {
    stop_with("-TERM", 143);
}

#[test]
fn ctrl_c_stops_cleanly_with_130() {
    stop_with("-INT", 130);
}

#[test]
fn a_second_signal_stops_at_once() {
    if !hooks() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let plant = plant(dir.path(), 3);
    let out = dir.path().join("out");
    let gate = dir.path().join("never");
    let child = spawn(
        &batch_args(&plant, &out, &["--threads", "1"]),
        &[("STICTION_TEST_GATE", s(&gate))],
    );
    wait_for("the first loop file", || json_files(&out.join("loops")) > 0);
    // two different signals are never merged into one by the kernel
    signal(&child, "-TERM");
    signal(&child, "-INT");
    // the gate never opens: only the second signal can end this run
    let o = finish(child, "the run signalled twice");
    assert!(
        matches!(o.status.code(), Some(130 | 143)),
        "{:?}: {}",
        o.status,
        stderr(&o)
    );
}

#[test]
fn a_full_disk_stops_with_the_file_named_and_resume_completes_the_summary() {
    if !hooks() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let plant = plant(dir.path(), 5);
    let reference = dir.path().join("reference");
    let o = run(&batch_args(&plant, &reference, &["--reports"]), &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let want = summary(&reference);
    // every write of the run in turn is the first to meet the full disk: batch.json, the empty
    // summary (csv, json), each loop's JSON and report, the final summary and index
    let writes = 1 + 2 + 2 * 5 + 3;
    for n in 1..=writes {
        let out = dir.path().join(format!("out{n}"));
        let args = batch_args(&plant, &out, &["--reports", "--threads", "1"]);
        let o = run(&args, &[("STICTION_TEST_FAIL_WRITE", &n.to_string())]);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "write {n}: {err}");
        // one error line; a progress line may come before it on a slow (loaded) machine, when
        // the batch passes a tenth of its loops more than a second after it started
        let errors = err
            .trim()
            .lines()
            .filter(|l| !(l.starts_with("batch: ") && l.contains(" loops/s")))
            .count();
        assert_eq!(errors, 1, "write {n}: {err}");
        assert!(err.contains("no space left on device"), "write {n}: {err}");
        assert!(err.contains("cannot write the file"), "write {n}: {err}");
        assert!(err.contains("free space"), "write {n}: {err}");
        if n > 3 {
            assert!(err.contains("--resume"), "write {n}: {err}");
        }
        assert!(temps(&out).is_empty(), "write {n}: {:?}", temps(&out));
        // a summary is whole or absent, never half written
        if let Ok(text) = std::fs::read_to_string(out.join("summary.csv")) {
            assert!(text.starts_with("loop_id,source,verdict"), "write {n}");
            assert!(text.ends_with('\n'), "write {n}");
        }
        // space freed: --resume gives the undisturbed summary, with no temporary file anywhere
        let o = run(&[&args[..], &["--resume"]].concat(), &[]);
        assert!(o.status.success(), "write {n}, resume: {}", stderr(&o));
        assert_eq!(summary(&out), want, "write {n}");
        assert!(temps(&out).is_empty(), "write {n}: {:?}", temps(&out));
    }
}

#[test]
fn kill_9_at_twenty_random_moments_then_resume_gives_the_undisturbed_summary() {
    let dir = tempfile::tempdir().unwrap();
    let plant = plant(dir.path(), 8);
    let reference = dir.path().join("reference");
    let start = Instant::now();
    let o = run(&batch_args(&plant, &reference, &["--reports"]), &[]);
    let took = start.elapsed();
    assert!(o.status.success(), "{}", stderr(&o));
    let want = summary(&reference);
    assert_eq!(want.len(), 8);
    // xorshift64 from a fixed seed: the moments, as fractions of an undisturbed run's time
    let mut state: u64 = 0x5eed_2026;
    for k in 0..20 {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        let fraction = (state % 1000) as f64 / 1000.0 * 0.9;
        let out = dir.path().join(format!("out{k}"));
        let args = batch_args(&plant, &out, &["--reports"]);
        let mut child = spawn(&args, &[]);
        std::thread::sleep(took.mul_f64(fraction));
        let _ = child.kill(); // SIGKILL; it may have finished already
        child.wait().unwrap();
        let o = run(&[&args[..], &["--resume"]].concat(), &[]);
        assert!(
            o.status.success(),
            "kill {k} at {fraction:.2} of the run: {}",
            stderr(&o)
        );
        assert_eq!(summary(&out), want, "kill {k} at {fraction:.2} of the run");
        assert!(temps(&out).is_empty(), "kill {k}: {:?}", temps(&out));
    }
}

#[test]
fn summary_cells_never_run_as_formulas() {
    let dir = tempfile::tempdir().unwrap();
    let folder = dir.path().join("=SUM(1+1)");
    std::fs::create_dir_all(&folder).unwrap();
    closed_stenman(&folder.join("+cmd.csv"), "2", &["--noise", "0.05"]);
    std::fs::write(folder.join("-bad.csv"), "t,sp,op,pv\n0,1,@x,2\n").unwrap();
    let out = dir.path().join("out");
    // run from the temporary folder, so the source column starts with the folder's name
    let o = bin()
        .current_dir(dir.path())
        .args([
            "batch",
            "=SUM(1+1)",
            "-o",
            "out",
            "--sp",
            "sp",
            "--no-quantify",
        ])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    let rows = summary(&out);
    let ids: Vec<&str> = rows.iter().map(|r| r["loop_id"].as_str()).collect();
    assert_eq!(ids, ["'+cmd", "'-bad"]);
    for r in &rows {
        assert!(r["source"].starts_with("'=SUM(1+1)/"), "{r:?}");
    }
    assert!(
        rows[1]["error"].starts_with("'=SUM(1+1)/-bad.csv"),
        "{:?}",
        rows[1]
    );
    // the loop ids stay the file names; summary.json keeps the text as it is
    assert!(out.join("loops/+cmd.json").exists());
    let j: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(j["rows"][0]["loop_id"], "+cmd");
}

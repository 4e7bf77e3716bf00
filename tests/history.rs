//! `harness history`: the store through the command line (record twice, a corrupted store), the
//! page of a small history in Chromium, and `history run` / `history find` on a toy repository
//! whose "harness" is a tiny crate that writes a results.json from a number in the commit.

mod support;

use std::path::{Path, PathBuf};
use std::process::Command;

use harness::history::collect::{self, CollectOptions, FindTarget, Outcome};
use harness::history::measures::Measure;
use harness::history::store::{HistoryStore, Mixing, Recorded};
use harness::history::{page, timeline};

fn git(repo: &Path, args: &[&str]) -> String {
    let out = Command::new("git")
        .arg("-C")
        .arg(repo)
        .args(["-c", "user.name=t", "-c", "user.email=t@t", "-c", "commit.gpgsign=false"])
        .args(args)
        .output()
        .unwrap();
    assert!(out.status.success(), "git {args:?}: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8_lossy(&out.stdout).trim().to_string()
}

/// A repository of `n` commits (each changing `note.txt`); their hashes, oldest first.
fn repository(dir: &Path, n: usize) -> Vec<String> {
    git(dir, &["init", "--quiet", "-b", "main"]);
    (0..n)
        .map(|i| {
            std::fs::write(dir.join("note.txt"), format!("{i}\n")).unwrap();
            git(dir, &["add", "-A"]);
            git(dir, &["commit", "--quiet", "-m", &format!("commit {i}")]);
            git(dir, &["rev-parse", "HEAD"])
        })
        .collect()
}

/// A results.json of `commit`: bar / arap with `e_theta` and a time per edit of `seconds` spread
/// by +-2%.
fn results_json(commit: &str, e_theta: f64, seconds: f64) -> String {
    format!(
        r#"{{"data_source":"survey","provenance":{{"machine":{{"cpu_model":"Test CPU","logical_cores":2,"memory_gib":8}},
        "build":{{"git_commit":"{commit}","git_dirty":false}},"run":{{"started_utc":"2026-12-06T00:00:00Z","threads":2,"jobs":1,"repetitions":3}},
        "inputs":[{{"path":"/data/bar.off","sha256":"ab"}}]}},
        "cases":[{{"scenario":"bar","method":"arap","status":"ok","bind_s":0.0,"solve_s":{seconds},"precompute_s":0.1,"iterations":40,
        "peak_memory_mib":10.0,"e_theta_deg":{e_theta},"steps":[{{}}],
        "spread":{{"bind_s":{{"min":0.0,"max":0.0}},"solve_s":{{"min":{lo},"max":{hi}}},"precompute_s":{{"min":0.1,"max":0.1}}}}}}]}}"#,
        lo = seconds * 0.98,
        hi = seconds * 1.02
    )
}

fn cli(args: &[&str]) -> anyhow::Result<std::process::ExitCode> {
    harness::cli::run(std::iter::once("harness").chain(args.iter().copied()))
}

#[test]
fn recording_twice_adds_nothing_and_the_page_names_the_commit_of_a_step() {
    let dir = tempfile::tempdir().unwrap();
    let repo = dir.path().join("repo");
    std::fs::create_dir(&repo).unwrap();
    let commits = repository(&repo, 8);
    let store = dir.path().join("history.sqlite");
    let mut files: Vec<PathBuf> = Vec::new();
    for (i, c) in commits.iter().enumerate() {
        // E_theta steps up at commit 5; the time wobbles within its noise.
        let e_theta = if i < 5 { 1.0 } else { 1.4 };
        let seconds = 2.0 * (1.0 + 0.03 * ((i * 7 % 5) as f64 - 2.0) / 2.0);
        let file = dir.path().join(format!("run{i}.json"));
        std::fs::write(&file, results_json(c, e_theta, seconds)).unwrap();
        files.push(file);
    }
    let mut args = vec!["history", "record", "--store", store.to_str().unwrap()];
    args.extend(files.iter().map(|f| f.to_str().unwrap()));
    cli(&args).unwrap();
    let counts = |s: &Path| {
        let s = HistoryStore::open_existing(s).unwrap();
        (s.runs().unwrap().len(), s.values().unwrap().len())
    };
    let first = counts(&store);
    assert_eq!(first.0, 8);
    cli(&args).unwrap();
    assert_eq!(counts(&store), first, "recording the same runs again added rows");

    let out = dir.path().join("page");
    cli(&[
        "history",
        "show",
        "--store",
        store.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--repo",
        repo.to_str().unwrap(),
    ])
    .unwrap();
    let history = timeline::build(&HistoryStore::open_existing(&store).unwrap(), &repo).unwrap();
    let steps = page::all_steps(&history);
    let described: Vec<String> = steps
        .iter()
        .map(|(t, s)| format!("{} {}", t.measure.key(), page::step_commit(&history, s)))
        .collect();
    assert_eq!(described.len(), 1, "{described:?}");
    assert!(
        described[0].starts_with("e_theta_deg") && described[0].contains(&commits[5][..7]),
        "{described:?}"
    );
    let index = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(
        index.contains("class=\"history-case\"") && index.contains("bar / arap"),
        "no section for bar / arap"
    );
    assert!(index.contains(&commits[5][..7]));
    assert!(std::fs::read_to_string(out.join("steps.md")).unwrap().contains("e_theta_deg"));

    let Some(chromium) = support::chromium() else { return };
    let (loaded, total) = support::images_loaded_in_chromium(&chromium, &out.join("index.html"));
    assert_eq!((loaded, total), (1, 1), "the section's timeline figure did not load");
    let dom = support::dump_dom(&chromium, &format!("file://{}", out.join("index.html").display())).0;
    let section = dom.split("class=\"history-case\"").nth(1).expect("the section is in the rendered DOM");
    assert!(
        section.contains("e_theta_deg") && section.contains(&commits[5][..7]),
        "the section lists its step"
    );
}

#[test]
fn a_corrupted_store_is_an_error_and_is_not_overwritten() {
    let dir = tempfile::tempdir().unwrap();
    let store = dir.path().join("history.sqlite");
    let run = dir.path().join("run.json");
    std::fs::write(&run, results_json("abc", 1.0, 1.0)).unwrap();
    cli(&["history", "record", "--store", store.to_str().unwrap(), run.to_str().unwrap()]).unwrap();
    // Cut the file short, as a disk that filled up or a copy that was interrupted would.
    let bytes = std::fs::read(&store).unwrap();
    std::fs::write(&store, &bytes[..bytes.len() / 2]).unwrap();
    let before = std::fs::read(&store).unwrap();
    for args in [
        vec!["history", "record", "--store", store.to_str().unwrap(), run.to_str().unwrap()],
        vec![
            "history",
            "show",
            "--store",
            store.to_str().unwrap(),
            "--out",
            dir.path().join("page").to_str().unwrap(),
        ],
    ] {
        let message = format!("{:#}", cli(&args).unwrap_err());
        assert!(
            message.contains(store.to_str().unwrap()) && message.contains("not a usable history store"),
            "{message}"
        );
    }
    assert_eq!(std::fs::read(&store).unwrap(), before, "the store was written to");
    // A results.json that is not one is refused before the store is opened.
    let bad = dir.path().join("bad.json");
    std::fs::write(&bad, "{\"cases\": []}").unwrap();
    let fresh = dir.path().join("fresh.sqlite");
    let message = format!(
        "{:#}",
        cli(&["history", "record", "--store", fresh.to_str().unwrap(), bad.to_str().unwrap()]).unwrap_err()
    );
    assert!(message.contains("bad.json") && message.contains("data_source"), "{message}");
    assert!(!fresh.exists(), "a refused record made a store");
}

/// A toy repository whose `harness` crate writes a results.json with `iterations` read from
/// `value.txt` at build time: commit i holds `values[i]`; `broken` commits do not compile.
fn toy_repository(dir: &Path, values: &[u32], broken: &[usize]) -> Vec<String> {
    git(dir, &["init", "--quiet", "-b", "main"]);
    std::fs::write(dir.join("Cargo.toml"), "[workspace]\nmembers = [\"harness\"]\nresolver = \"2\"\n")
        .unwrap();
    std::fs::create_dir_all(dir.join("harness/src")).unwrap();
    std::fs::write(
        dir.join("harness/Cargo.toml"),
        "[package]\nname = \"harness\"\nversion = \"0.1.0\"\nedition = \"2021\"\n",
    )
    .unwrap();
    std::fs::write(dir.join(".gitignore"), "Cargo.lock\n").unwrap();
    let main = r#"fn main() {
    let args: Vec<String> = std::env::args().collect();
    let reports = &args[args.iter().position(|a| a == "--reports").unwrap() + 1];
    let head = std::process::Command::new("git").args(["rev-parse", "HEAD"]).output().unwrap().stdout;
    let commit = String::from_utf8(head).unwrap();
    let iterations: u32 = include_str!("../../value.txt").trim().parse().unwrap();
    std::fs::create_dir_all(reports).unwrap();
    let json = format!(
        "{{\"data_source\":\"survey\",\"provenance\":{{\"machine\":{{\"cpu_model\":\"toy\",\"logical_cores\":1,\"memory_gib\":1}},\"build\":{{\"git_commit\":\"{}\",\"git_dirty\":false}},\"run\":{{\"started_utc\":\"x\",\"threads\":1,\"jobs\":1,\"repetitions\":1}}}},\"cases\":[{{\"scenario\":\"bar\",\"method\":\"arap\",\"status\":\"ok\",\"bind_s\":0.1,\"solve_s\":0.2,\"iterations\":{},\"e_theta_deg\":1.0}}]}}",
        commit.trim(),
        iterations
    );
    std::fs::write(format!("{reports}/results.json"), json).unwrap();
}
"#;
    values
        .iter()
        .enumerate()
        .map(|(i, v)| {
            std::fs::write(dir.join("value.txt"), format!("{v}\n")).unwrap();
            let source = if broken.contains(&i) { "fn main() { this does not compile }\n" } else { main };
            std::fs::write(dir.join("harness/src/main.rs"), source).unwrap();
            git(dir, &["add", "-A"]);
            git(dir, &["commit", "--quiet", "--allow-empty", "-m", &format!("commit {i}")]);
            git(dir, &["rev-parse", "HEAD"])
        })
        .collect()
}

#[test]
fn history_run_resumes_and_find_bisects_a_step_to_its_commit() {
    let dir = tempfile::tempdir().unwrap();
    let repo = dir.path().join("toy");
    std::fs::create_dir(&repo).unwrap();
    // Iterations go from 40 to 55 at commit 5; commit 3 does not build.
    let commits = toy_repository(&repo, &[40, 40, 40, 40, 40, 55, 55, 55], &[3]);
    let path = dir.path().join("history.sqlite");
    let mut store = HistoryStore::open_or_create(&path).unwrap();
    let options = CollectOptions {
        repo: repo.clone(),
        work_dir: dir.path().join("work"),
        suite_args: Vec::new(),
        retry_failed: false,
        mixing: Mixing::Refuse,
    };
    let ends = vec![commits[0].clone(), commits[7].clone()];
    let outcomes = collect::run_commits(&mut store, &ends, &options, |_, _, _| {}).unwrap();
    assert!(outcomes.iter().all(|o| matches!(o, Outcome::Recorded(Recorded::Added { .. }))), "{outcomes:?}");
    // Run again, as after a kill: nothing is run twice.
    let again = collect::run_commits(&mut store, &ends, &options, |_, _, _| {}).unwrap();
    assert_eq!(again, vec![Outcome::AlreadyRecorded, Outcome::AlreadyRecorded]);
    // A commit that does not build is kept as failed and skipped next time.
    let broken = collect::run_commits(&mut store, &commits[3..4], &options, |_, _, _| {}).unwrap();
    assert!(matches!(&broken[0], Outcome::Failed { stage, .. } if stage == "build"), "{broken:?}");
    let broken = collect::run_commits(&mut store, &commits[3..4], &options, |_, _, _| {}).unwrap();
    assert!(matches!(&broken[0], Outcome::FailedBefore(_)), "{broken:?}");

    let history = timeline::build(&store, &repo).unwrap();
    let step = &history.timelines.iter().find(|t| t.measure == Measure::Iterations).unwrap().steps;
    assert_eq!(step.len(), 1);
    assert_eq!(step[0].made_by, None, "commits 0 and 7 are not parent and child");

    let target = FindTarget { measure: Measure::Iterations, scenario: Some("bar".into()), method: None };
    let mut ran = Vec::new();
    let found = collect::find(&mut store, &target, &options, |sha, _| ran.push(sha.to_string())).unwrap();
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!(found[0].commit.sha, commits[5], "the step is commit 5's");
    assert_eq!((found[0].step.before, found[0].step.after), (40.0, 55.0));
    assert!(ran.len() <= 3 && !ran.contains(&commits[3]), "bisection ran {ran:?}");
}

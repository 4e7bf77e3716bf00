//! Where and how a run was made, written at the top of `results.json` and of the page: the machine
//! (CPU, logical cores, memory, OS and kernel), the build (crate version, git commit of the checkout
//! the binary was built from, whether its tree was dirty then and the SHA-256 of its diff, rustc,
//! profile; all compiled in by `build.rs`) and the run (start time,
//! command line, threads, jobs, repetitions). Anything that cannot be read is `unknown`, never an
//! error: a record is a courtesy to the reader, not a precondition of the run.

// Also compiled into build.rs, which uses all of it; the library itself needs only the diff hash.
#[allow(dead_code)]
mod git_state;

pub use git_state::diff_sha256;
use serde::{Deserialize, Serialize};

/// The record of one run.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Provenance {
    pub machine: Machine,
    pub build: Build,
    pub run: RunRecord,
    /// Every mesh, selection, transform and config file the run read, with its SHA-256.
    #[serde(default)]
    pub inputs: Vec<InputFile>,
    /// What each external method said it is (its `about`: interpreter, library and version).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub external: Vec<ExternalRecord>,
    /// A merge's parts (`all --shard K/N`), each with its own record, in part order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub parts: Vec<Provenance>,
}

#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Machine {
    /// `model name` of /proc/cpuinfo.
    pub cpu_model: String,
    pub logical_cores: usize,
    /// MemTotal of /proc/meminfo, GiB.
    pub memory_gib: f64,
    /// PRETTY_NAME of /etc/os-release.
    pub os: String,
    pub kernel: String,
}

#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Build {
    /// The harness crate's version.
    pub version: String,
    /// `git rev-parse HEAD` of the checkout this binary was built from, when it was one.
    pub git_commit: Option<String>,
    /// Whether tracked files differed from that commit when the binary was built.
    pub git_dirty: Option<bool>,
    /// When dirty: the SHA-256 of the uncommitted change ([`diff_sha256`]), so that runs of two
    /// states of one commit's tree are told apart (the history keeps them as points of their own).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub git_diff_sha256: Option<String>,
    pub rustc: String,
    /// `release` or `debug`.
    pub profile: String,
}

#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RunRecord {
    /// Start of the run, UTC, `YYYY-MM-DDTHH:MM:SSZ`.
    pub started_utc: String,
    pub command_line: Vec<String>,
    /// Worker threads of every method (`--threads`).
    pub threads: usize,
    /// Cases run at a time.
    pub jobs: usize,
    /// Repetitions of each case's timed phases.
    pub repetitions: usize,
}

const UNKNOWN: &str = "unknown";

impl Provenance {
    /// The record of a run started now with `command_line`: `jobs` cases at a time, each on `threads`
    /// worker threads and timed `repetitions` times.
    pub fn record(command_line: Vec<String>, threads: usize, jobs: usize, repetitions: usize) -> Self {
        Provenance {
            machine: Machine::read(),
            build: Build::read(),
            run: RunRecord {
                started_utc: utc_timestamp(std::time::SystemTime::now()),
                command_line,
                threads,
                jobs,
                repetitions,
            },
            inputs: Vec::new(),
            external: Vec::new(),
            parts: Vec::new(),
        }
    }

    /// One line for the page and the console.
    pub fn summary(&self) -> String {
        let m = &self.machine;
        let b = &self.build;
        let commit = match (&b.git_commit, b.git_dirty) {
            (Some(c), Some(true)) => match &b.git_diff_sha256 {
                Some(d) => format!("{} (dirty, diff {})", &c[..c.len().min(12)], &d[..d.len().min(12)]),
                None => format!("{} (dirty)", &c[..c.len().min(12)]),
            },
            (Some(c), _) => c[..c.len().min(12)].to_string(),
            (None, _) => UNKNOWN.to_string(),
        };
        let parts = match self.parts.len() {
            0 => String::new(),
            n => format!("; merged from {n} parts run on {}", {
                let mut machines: Vec<&str> =
                    self.parts.iter().map(|p| p.machine.cpu_model.as_str()).collect();
                machines.dedup();
                machines.join(", ")
            }),
        };
        format!(
            "run {} on {} ({} logical cores, {:.0} GiB, {}, kernel {}); harness {} at {commit}, {}, {} profile; {} thread(s), {} job(s), {} repetition(s){parts}",
            self.run.started_utc,
            m.cpu_model,
            m.logical_cores,
            m.memory_gib,
            m.os,
            m.kernel,
            b.version,
            b.rustc,
            b.profile,
            self.run.threads,
            self.run.jobs,
            self.run.repetitions
        )
    }
}

impl Machine {
    pub fn read() -> Self {
        let cpuinfo = std::fs::read_to_string("/proc/cpuinfo").unwrap_or_default();
        let cpu_model = field(&cpuinfo, "model name", ':').unwrap_or_else(|| UNKNOWN.into());
        let meminfo = std::fs::read_to_string("/proc/meminfo").unwrap_or_default();
        let memory_kib: f64 = field(&meminfo, "MemTotal", ':')
            .and_then(|v| v.split_whitespace().next().and_then(|n| n.parse().ok()))
            .unwrap_or(f64::NAN);
        let os_release = std::fs::read_to_string("/etc/os-release").unwrap_or_default();
        let os = field(&os_release, "PRETTY_NAME", '=')
            .map(|v| v.trim_matches('"').to_string())
            .unwrap_or_else(|| std::env::consts::OS.to_string());
        let kernel = std::fs::read_to_string("/proc/sys/kernel/osrelease")
            .map(|s| s.trim().to_string())
            .unwrap_or_else(|_| UNKNOWN.into());
        Machine {
            cpu_model,
            logical_cores: crate::threads::logical_cores(),
            memory_gib: memory_kib / (1024.0 * 1024.0),
            os,
            kernel,
        }
    }
}

impl Build {
    /// The build this binary is: the git state of its checkout when it was compiled (`build.rs`),
    /// not the checkout's state now. A binary copied away, or kept while the checkout moved on,
    /// still records the commit and diff it was built from.
    fn read() -> Self {
        let compiled = |value: &'static str| Some(value.to_string()).filter(|v| !v.is_empty());
        Build {
            version: env!("CARGO_PKG_VERSION").to_string(),
            git_commit: compiled(env!("DEFORMBENCH_GIT_COMMIT")),
            git_dirty: compiled(env!("DEFORMBENCH_GIT_DIRTY")).map(|d| d == "true"),
            git_diff_sha256: compiled(env!("DEFORMBENCH_GIT_DIFF_SHA256")),
            rustc: env!("DEFORMBENCH_RUSTC_VERSION").to_string(),
            profile: env!("DEFORMBENCH_PROFILE").to_string(),
        }
    }
}

/// An external method and its own account of itself.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ExternalRecord {
    pub method: String,
    pub about: String,
}

/// The `about` of every external method of `results`, once per method.
pub fn external_records(results: &[crate::record::CaseResult]) -> Vec<ExternalRecord> {
    let mut out: Vec<ExternalRecord> = Vec::new();
    for r in results.iter().filter(|r| r.origin != crate::config::Origin::BuiltIn) {
        if let Some(about) = &r.about {
            if !out.iter().any(|e| e.method == r.method) {
                out.push(ExternalRecord { method: r.method.clone(), about: about.clone() });
            }
        }
    }
    out
}

/// One input file and its SHA-256 (hex).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct InputFile {
    pub path: String,
    pub sha256: String,
}

/// The SHA-256 of every file of `paths` that exists (once each, in order; a glob pattern or a
/// directory is skipped).
pub fn hash_inputs(paths: impl IntoIterator<Item = std::path::PathBuf>) -> Vec<InputFile> {
    use sha2::Digest;
    let mut out: Vec<InputFile> = Vec::new();
    for path in paths {
        let name = path.display().to_string();
        if !path.is_file() || out.iter().any(|f| f.path == name) {
            continue;
        }
        let Ok(mut file) = std::fs::File::open(&path) else { continue };
        let mut hasher = sha2::Sha256::new();
        if std::io::copy(&mut file, &mut hasher).is_err() {
            continue;
        }
        let digest = hasher.finalize();
        out.push(InputFile { path: name, sha256: digest.iter().map(|b| format!("{b:02x}")).collect() });
    }
    out
}

/// The value of the first line `key<sep> value` of `text`, trimmed.
fn field(text: &str, key: &str, separator: char) -> Option<String> {
    text.lines().find_map(|line| {
        let (k, v) = line.split_once(separator)?;
        (k.trim() == key).then(|| v.trim().to_string())
    })
}

/// `time` as `YYYY-MM-DDTHH:MM:SSZ` (UTC; civil date from days since 1970, Howard Hinnant's
/// algorithm).
pub fn utc_timestamp(time: std::time::SystemTime) -> String {
    let seconds = time.duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_secs()) as i64;
    let (days, of_day) = (seconds.div_euclid(86_400), seconds.rem_euclid(86_400));
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!(
        "{year:04}-{month:02}-{day:02}T{:02}:{:02}:{:02}Z",
        of_day / 3600,
        of_day % 3600 / 60,
        of_day % 60
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::{Duration, UNIX_EPOCH};

    #[test]
    fn timestamps_are_civil_utc() {
        assert_eq!(utc_timestamp(UNIX_EPOCH), "1970-01-01T00:00:00Z");
        // 2000-02-29 12:34:56 UTC, a leap day.
        assert_eq!(utc_timestamp(UNIX_EPOCH + Duration::from_secs(951_827_696)), "2000-02-29T12:34:56Z");
        assert_eq!(utc_timestamp(UNIX_EPOCH + Duration::from_secs(1_796_256_000)), "2026-12-03T00:00:00Z");
    }

    #[test]
    fn the_record_of_this_machine_is_sane() {
        let p = Provenance::record(vec!["harness".into(), "all".into()], 3, 2, 1);
        assert!(p.machine.logical_cores >= 1);
        assert!(p.machine.memory_gib > 0.1 && p.machine.memory_gib < 1e5, "{}", p.machine.memory_gib);
        assert!(!p.machine.cpu_model.is_empty() && !p.machine.kernel.is_empty());
        assert!(p.build.rustc.starts_with("rustc "), "{}", p.build.rustc);
        assert!(["release", "debug"].contains(&p.build.profile.as_str()), "{}", p.build.profile);
        if let Some(commit) = &p.build.git_commit {
            assert!(commit.len() == 40 && commit.chars().all(|c| c.is_ascii_hexdigit()), "{commit}");
        }
        assert_eq!((p.run.threads, p.run.jobs, p.run.repetitions), (3, 2, 1));
        assert!(p.run.started_utc.starts_with("20") && p.run.started_utc.ends_with('Z'));
        let line = p.summary();
        assert!(line.contains("3 thread(s), 2 job(s)") && line.contains(&p.machine.kernel), "{line}");
    }

    #[test]
    fn inputs_are_hashed_once_and_missing_ones_skipped() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("abc.txt");
        std::fs::write(&file, "abc").unwrap();
        let inputs =
            hash_inputs([file.clone(), dir.path().join("*.off"), file.clone(), dir.path().to_path_buf()]);
        assert_eq!(inputs.len(), 1);
        // FIPS 180-2's test vector.
        assert_eq!(inputs[0].sha256, "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
    }

    /// `git -C repo args...` with a throwaway identity, asserted to succeed; its trimmed output.
    fn git_in(repo: &std::path::Path, args: &[&str]) -> String {
        let out = std::process::Command::new("git")
            .arg("-C")
            .arg(repo)
            .args(["-c", "user.name=t", "-c", "user.email=t@t", "-c", "commit.gpgsign=false"])
            .args(args)
            .output()
            .unwrap();
        assert!(out.status.success(), "git {args:?}: {}", String::from_utf8_lossy(&out.stderr));
        String::from_utf8_lossy(&out.stdout).trim().to_string()
    }

    #[test]
    fn the_diff_hash_tells_states_of_a_tree_apart_and_ignores_untracked_files() {
        let dir = tempfile::tempdir().unwrap();
        let repo = dir.path();
        let git = |args: &[&str]| {
            git_in(repo, args);
        };
        git(&["init", "--quiet"]);
        std::fs::write(repo.join("a.txt"), "one\n").unwrap();
        git(&["add", "a.txt"]);
        git(&["commit", "--quiet", "-m", "one"]);
        let clean = diff_sha256(repo).unwrap();
        std::fs::write(repo.join("a.txt"), "two\n").unwrap();
        let two = diff_sha256(repo).unwrap();
        std::fs::write(repo.join("a.txt"), "three\n").unwrap();
        let three = diff_sha256(repo).unwrap();
        assert!(clean != two && two != three, "{clean} {two} {three}");
        std::fs::write(repo.join("a.txt"), "two\n").unwrap();
        assert_eq!(diff_sha256(repo).unwrap(), two, "the same change, the same hash");
        git(&["add", "a.txt"]);
        assert_eq!(diff_sha256(repo).unwrap(), two, "staged or not, the same change");
        std::fs::write(repo.join("scratch.txt"), "untracked").unwrap();
        assert_eq!(diff_sha256(repo).unwrap(), two, "an untracked file is not part of it");
        assert_eq!(diff_sha256(&repo.join("no-such-dir")), None);
    }

    /// What build.rs compiles into the binary: the commit, dirtiness and diff of the checkout, and
    /// the files whose change moves `HEAD`.
    #[test]
    fn the_git_state_follows_commits_and_changes() {
        let dir = tempfile::tempdir().unwrap();
        let repo = dir.path();
        let git = |args: &[&str]| git_in(repo, args);
        git(&["init", "--quiet", "--initial-branch=trunk"]);
        std::fs::write(repo.join("a.txt"), "one\n").unwrap();
        git(&["add", "a.txt"]);
        git(&["commit", "--quiet", "-m", "one"]);
        let one = git_state::read(repo);
        assert_eq!(one.commit.as_deref(), Some(git(&["rev-parse", "HEAD"]).as_str()));
        assert_eq!((one.dirty, one.diff_sha256.as_deref()), (Some(false), None));
        std::fs::write(repo.join("a.txt"), "two\n").unwrap();
        let changed = git_state::read(repo);
        assert_eq!((changed.commit.as_ref(), changed.dirty), (one.commit.as_ref(), Some(true)));
        assert_eq!(changed.diff_sha256, diff_sha256(repo));
        git(&["commit", "--quiet", "-am", "two"]);
        let two = git_state::read(repo);
        assert!(two.commit != one.commit && two.dirty == Some(false));
        let files = git_state::head_files(repo);
        for name in ["HEAD", "packed-refs", "trunk"] {
            assert!(files.iter().any(|f| f.ends_with(name) && f.is_absolute()), "{name} in {files:?}");
        }
        assert_eq!(git_state::read(&repo.join("no-such-dir")), git_state::GitState::default());
    }

    #[test]
    fn fields_are_read_by_key() {
        assert_eq!(field("a : 1\nmodel name\t: Xeon\n", "model name", ':').as_deref(), Some("Xeon"));
        assert_eq!(
            field("NAME=x\nPRETTY_NAME=\"Debian\"\n", "PRETTY_NAME", '=').as_deref(),
            Some("\"Debian\"")
        );
        assert_eq!(field("", "x", ':'), None);
    }
}

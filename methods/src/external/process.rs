//! An external method's process: started in a process group of its own, spoken to line by line
//! with a timeout per request, its stderr logged (its first and last [`STDERR_LOG_KEEP`] bytes) and
//! its last lines kept for error messages, and killed with everything it started when dropped:
//! its process group, and every process that carries its [`PROCESS_TOKEN_ENV`], which catches
//! what left the group or the session (`setsid`, a daemon's double fork) with the environment
//! inherited.
//!
//! Reading and writing go through threads so that a program that stops reading its stdin (a hang, a
//! crash) can never block the harness: every request waits at most its timeout.

use std::collections::VecDeque;
use std::io::{BufRead, BufReader, Read, Write};
use std::os::unix::process::CommandExt;
use std::path::PathBuf;
use std::process::{Child, ChildStdin, Command, ExitStatus, Stdio};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, Sender};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// Lines of stderr kept for error messages.
pub const STDERR_TAIL_LINES: usize = 8;

/// Of a method's stderr the log keeps this many bytes from the start and as many from the end,
/// with a line saying how much was cut between them: a chatty method cannot fill the disk over a
/// large run.
pub const STDERR_LOG_KEEP: usize = 1 << 20;

/// The environment variable every method process gets, unique to that process (harness pid and a
/// counter); whatever it starts inherits it, so the descendants can be found after they left the
/// process group.
pub const PROCESS_TOKEN_ENV: &str = "DEFORMBENCH_PROCESS_TOKEN";

/// How long a program may take to exit after `quit` before it is killed.
const EXIT_GRACE: Duration = Duration::from_secs(2);

/// What went wrong talking to the process (the caller adds the method's name and the request).
#[derive(Debug)]
pub enum ProcessFault {
    /// The program could not be started.
    Start(std::io::Error),
    /// It closed its stdout or exited; its exit status when known.
    Exited(Option<ExitStatus>),
    /// No answer within the timeout.
    Timeout(Duration),
    /// Reading its stdout failed (not UTF-8, say).
    Read(std::io::Error),
}

impl std::fmt::Display for ProcessFault {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ProcessFault::Start(e) => write!(f, "could not be started: {e}"),
            ProcessFault::Exited(Some(status)) => write!(f, "exited ({status})"),
            ProcessFault::Exited(None) => write!(f, "closed its stdout"),
            ProcessFault::Timeout(t) => write!(f, "said nothing within its timeout of {} s", t.as_secs_f64()),
            ProcessFault::Read(e) => write!(f, "stdout could not be read: {e}"),
        }
    }
}

/// A running external program.
pub struct MethodProcess {
    child: Child,
    /// Lines to write to its stdin; dropping it closes stdin.
    requests: Option<Sender<String>>,
    /// Its stdout, line by line (`None`: end of file).
    answers: Receiver<Result<Option<String>, std::io::Error>>,
    stderr: Arc<Mutex<StderrTail>>,
    /// Signalled when the stderr reader has seen end of file (so the log is complete).
    stderr_done: Receiver<()>,
    killed: bool,
    /// [`PROCESS_TOKEN_ENV`]'s value for this process.
    token: String,
    /// Processes outside its group killed by the token when it ended, and those still alive after.
    escaped: Escaped,
}

/// What [`MethodProcess::kill`] found outside the program's process group.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Escaped {
    /// Processes that carried the program's token after its group was killed: killed.
    pub killed: Vec<u32>,
    /// Of those, the ones still running (not even a zombie) after the kill.
    pub alive: Vec<u32>,
}

/// The last [`STDERR_TAIL_LINES`] lines of stderr.
#[derive(Default)]
struct StderrTail {
    lines: VecDeque<String>,
}

impl MethodProcess {
    /// Start `program` with `args` in `working_dir` with `env` added; its stderr is written to
    /// `stderr_log` when given (replacing an earlier log).
    pub fn start(
        program: &str,
        args: &[String],
        working_dir: Option<&PathBuf>,
        env: &[(String, String)],
        stderr_log: Option<&PathBuf>,
    ) -> Result<Self, ProcessFault> {
        let mut command = Command::new(program);
        command.args(args).stdin(Stdio::piped()).stdout(Stdio::piped()).stderr(Stdio::piped());
        // A group of its own, so that killing the group also ends what the program started.
        command.process_group(0);
        if let Some(dir) = working_dir {
            command.current_dir(dir);
        }
        command.envs(env.iter().map(|(k, v)| (k, v)));
        static STARTED: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
        let token =
            format!("{}-{}", std::process::id(), STARTED.fetch_add(1, std::sync::atomic::Ordering::Relaxed));
        command.env(PROCESS_TOKEN_ENV, &token);
        let mut child = command.spawn().map_err(ProcessFault::Start)?;
        let stdin = child.stdin.take().expect("piped");
        let stdout = child.stdout.take().expect("piped");
        let stderr = child.stderr.take().expect("piped");

        let (requests, to_write) = mpsc::channel::<String>();
        std::thread::Builder::new()
            .name("external-stdin".into())
            .spawn(move || write_lines(stdin, to_write))
            .map_err(ProcessFault::Start)?;

        let (answer_tx, answers) = mpsc::channel();
        std::thread::Builder::new()
            .name("external-stdout".into())
            .spawn(move || read_lines(stdout, answer_tx))
            .map_err(ProcessFault::Start)?;

        let tail = Arc::new(Mutex::new(StderrTail::default()));
        let log = stderr_log.and_then(|path| {
            path.parent().map(std::fs::create_dir_all);
            std::fs::File::create(path).ok()
        });
        let (done_tx, stderr_done) = mpsc::channel();
        let tail_writer = Arc::clone(&tail);
        std::thread::Builder::new()
            .name("external-stderr".into())
            .spawn(move || {
                keep_stderr(stderr, log, &tail_writer);
                let _ = done_tx.send(());
            })
            .map_err(ProcessFault::Start)?;

        Ok(MethodProcess {
            child,
            requests: Some(requests),
            answers,
            stderr: tail,
            stderr_done,
            killed: false,
            token,
            escaped: Escaped::default(),
        })
    }

    /// Send `line` (with its newline) and wait up to `timeout` for one answer line.
    pub fn request(&mut self, line: String, timeout: Duration) -> Result<String, ProcessFault> {
        if let Some(requests) = &self.requests {
            // A send error means the writer thread ended (stdin broken): the answer wait below
            // then reports how the program ended.
            let _ = requests.send(line);
        }
        match self.answers.recv_timeout(timeout) {
            Ok(Ok(Some(answer))) => Ok(answer),
            Ok(Ok(None)) | Err(RecvTimeoutError::Disconnected) => {
                Err(ProcessFault::Exited(self.exit_status()))
            }
            Ok(Err(e)) => Err(ProcessFault::Read(e)),
            Err(RecvTimeoutError::Timeout) => Err(ProcessFault::Timeout(timeout)),
        }
    }

    /// The last lines of its stderr, oldest first (after [`kill`](Self::kill): to its end).
    pub fn stderr_tail(&self) -> Vec<String> {
        self.stderr.lock().map(|t| t.lines.iter().cloned().collect()).unwrap_or_default()
    }

    /// Kill the program and everything in its process group, then every process that still
    /// carries its token (it left the group), reap it, and let the stderr reader finish the log.
    pub fn kill(&mut self) {
        if self.killed {
            return;
        }
        self.requests = None;
        kill_group(self.child.id());
        let _ = self.child.wait();
        self.killed = true;
        self.escaped = kill_carriers(&self.token);
        let _ = self.stderr_done.recv_timeout(Duration::from_millis(500));
    }

    /// Ask the program to exit (`quit_line`, then end of input), give it [`EXIT_GRACE`], then kill
    /// what is left of its group.
    pub fn finish(&mut self, quit_line: String) {
        if self.killed {
            return;
        }
        if let Some(requests) = self.requests.take() {
            let _ = requests.send(quit_line);
        }
        let deadline = Instant::now() + EXIT_GRACE;
        while Instant::now() < deadline {
            if let Ok(Some(_)) = self.child.try_wait() {
                break;
            }
            std::thread::sleep(Duration::from_millis(5));
        }
        // Also ends any child the program left behind in its group.
        self.kill();
    }

    /// What the kill found outside the program's process group (empty before it ended).
    pub fn escaped(&self) -> &Escaped {
        &self.escaped
    }

    /// The exit status once the program has ended (waits up to a second for it to end).
    fn exit_status(&mut self) -> Option<ExitStatus> {
        let deadline = Instant::now() + Duration::from_secs(1);
        loop {
            match self.child.try_wait() {
                Ok(Some(status)) => return Some(status),
                Ok(None) if Instant::now() < deadline => std::thread::sleep(Duration::from_millis(5)),
                _ => return None,
            }
        }
    }
}

impl Drop for MethodProcess {
    fn drop(&mut self) {
        self.kill();
    }
}

/// SIGKILL to the process group `pgid` (the program's pid: it leads its own group).
fn kill_group(pgid: u32) {
    // SAFETY: kill(2) with a negative pid signals a process group; no memory is shared.
    unsafe {
        libc::kill(-(pgid as libc::pid_t), libc::SIGKILL);
    }
}

/// The processes whose environment holds `PROCESS_TOKEN_ENV=token`, other than this one.
fn carriers(token: &str) -> Vec<u32> {
    let needle = format!("{PROCESS_TOKEN_ENV}={token}\0");
    let me = std::process::id();
    let Ok(entries) = std::fs::read_dir("/proc") else { return Vec::new() };
    let mut out: Vec<u32> = entries
        .filter_map(|e| e.ok()?.file_name().to_str()?.parse::<u32>().ok())
        .filter(|&pid| pid != me)
        .filter(|pid| {
            std::fs::read(format!("/proc/{pid}/environ"))
                .is_ok_and(|env| env.windows(needle.len()).any(|w| w == needle.as_bytes()))
        })
        .collect();
    out.sort_unstable();
    out
}

/// Whether `pid` runs (exists and is not a zombie).
fn running(pid: u32) -> bool {
    std::fs::read_to_string(format!("/proc/{pid}/stat"))
        .is_ok_and(|stat| stat.rsplit(')').next().is_some_and(|rest| !rest.trim_start().starts_with('Z')))
}

/// SIGKILL every process carrying `token` (they left the program's group), then which still run.
///
/// The carriers are looked for again after every kill until none runs (or half a second has
/// passed): one that forked between the look and the kill has a child carrying the token too.
fn kill_carriers(token: &str) -> Escaped {
    let deadline = Instant::now() + Duration::from_millis(500);
    let mut killed: Vec<u32> = Vec::new();
    loop {
        let found: Vec<u32> = carriers(token).into_iter().filter(|&pid| running(pid)).collect();
        if found.is_empty() {
            return Escaped { killed, alive: Vec::new() };
        }
        for &pid in &found {
            // SAFETY: kill(2) on a pid; no memory is shared.
            unsafe {
                libc::kill(pid as libc::pid_t, libc::SIGKILL);
            }
            if !killed.contains(&pid) {
                killed.push(pid);
            }
        }
        std::thread::sleep(Duration::from_millis(10));
        if Instant::now() >= deadline {
            let alive = found.into_iter().filter(|&pid| running(pid)).collect();
            return Escaped { killed, alive };
        }
    }
}

fn write_lines(mut stdin: ChildStdin, lines: Receiver<String>) {
    for line in lines {
        if stdin.write_all(line.as_bytes()).and_then(|()| stdin.flush()).is_err() {
            return;
        }
    }
    // Dropping stdin here closes it: end of input for the program.
}

fn read_lines(stdout: impl Read, answers: Sender<Result<Option<String>, std::io::Error>>) {
    let mut reader = BufReader::with_capacity(1 << 20, stdout);
    loop {
        let mut line = String::new();
        let message = match reader.read_line(&mut line) {
            Ok(0) => Ok(None),
            Ok(_) => Ok(Some(line)),
            Err(e) => Err(e),
        };
        let last = !matches!(message, Ok(Some(_)));
        if answers.send(message).is_err() || last {
            return;
        }
    }
}

fn keep_stderr(stderr: impl Read, log: Option<std::fs::File>, tail: &Mutex<StderrTail>) {
    let mut reader = BufReader::new(stderr);
    let mut log = log.map(CappedLog::new);
    let mut bytes = Vec::new();
    loop {
        bytes.clear();
        match reader.read_until(b'\n', &mut bytes) {
            Ok(0) | Err(_) => {
                if let Some(log) = log.take() {
                    log.close();
                }
                return;
            }
            Ok(_) => {
                if let Some(log) = &mut log {
                    log.write(&bytes);
                }
                let line = String::from_utf8_lossy(&bytes).trim_end().to_string();
                if let Ok(mut tail) = tail.lock() {
                    if tail.lines.len() == STDERR_TAIL_LINES {
                        tail.lines.pop_front();
                    }
                    tail.lines.push_back(line);
                }
            }
        }
    }
}

/// A stderr log that keeps the first and the last [`STDERR_LOG_KEEP`] bytes: the head is written
/// as it comes, the tail held until the stream ends, with a line saying how much was cut.
struct CappedLog {
    file: std::fs::File,
    head: usize,
    tail: VecDeque<u8>,
    cut: u64,
}

impl CappedLog {
    fn new(file: std::fs::File) -> Self {
        CappedLog { file, head: 0, tail: VecDeque::new(), cut: 0 }
    }

    fn write(&mut self, mut bytes: &[u8]) {
        if self.head < STDERR_LOG_KEEP {
            let n = bytes.len().min(STDERR_LOG_KEEP - self.head);
            let _ = self.file.write_all(&bytes[..n]);
            self.head += n;
            bytes = &bytes[n..];
        }
        self.tail.extend(bytes);
        let over = self.tail.len().saturating_sub(STDERR_LOG_KEEP);
        if over > 0 {
            self.tail.drain(..over);
            self.cut += over as u64;
        }
    }

    fn close(mut self) {
        if self.cut > 0 {
            let _ = writeln!(
                self.file,
                "\n[deformbench: {} bytes of stderr cut here; the log keeps the first and the last {} bytes]",
                self.cut, STDERR_LOG_KEEP
            );
        }
        let (a, b) = self.tail.as_slices();
        let _ = self.file.write_all(a).and_then(|()| self.file.write_all(b));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_long_log_keeps_its_head_and_tail_and_says_what_was_cut() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("log");
        let mut log = CappedLog::new(std::fs::File::create(&path).unwrap());
        let line = |i: usize| format!("line {i:08}\n");
        let n = 3 * STDERR_LOG_KEEP / line(0).len();
        for i in 0..n {
            log.write(line(i).as_bytes());
        }
        log.close();
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.starts_with(&line(0)));
        assert!(text.ends_with(&line(n - 1)));
        let cut = n * line(0).len() - 2 * STDERR_LOG_KEEP;
        assert!(
            text.contains(&format!("[deformbench: {cut} bytes of stderr cut here")),
            "{}",
            &text[STDERR_LOG_KEEP - 40..STDERR_LOG_KEEP + 120]
        );
        assert!(text.len() < 2 * STDERR_LOG_KEEP + 200);
    }

    #[test]
    fn a_short_log_is_kept_whole() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("log");
        let mut log = CappedLog::new(std::fs::File::create(&path).unwrap());
        log.write(b"one\n");
        log.write(b"two\n");
        log.close();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "one\ntwo\n");
    }

    /// A program that double-forks a sleeper into a session of its own (as a daemon does) leaves
    /// nothing running once it is killed: the sleeper left the group but carries the token.
    #[test]
    fn a_child_that_left_the_session_is_killed_with_its_program() {
        let script = "setsid sh -c 'sleep 300' & sleep 300";
        let mut p = MethodProcess::start("sh", &["-c".into(), script.into()], None, &[], None).unwrap();
        let token = p.token.clone();
        // The session (field 6 of /proc/<pid>/stat) of a process.
        let session = |pid: u32| -> Option<String> {
            let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
            stat.rsplit(')').next()?.split_whitespace().nth(3).map(str::to_string)
        };
        // Wait until the sleeper has left the session, not only until it was forked: killed while
        // still in the program's group, it would go with the group and never be an escapee.
        let escaped = || {
            let ours = session(p.child.id());
            carriers(&token).into_iter().any(|pid| session(pid).is_some_and(|s| Some(s) != ours))
        };
        let deadline = Instant::now() + Duration::from_secs(10);
        while !(carriers(&token).len() >= 3 && escaped()) && Instant::now() < deadline {
            std::thread::sleep(Duration::from_millis(20));
        }
        let before = carriers(&token);
        assert!(
            before.len() >= 3 && escaped(),
            "sh, its sleep and the setsid one, out of the session: {before:?}"
        );
        p.kill();
        let after: Vec<u32> = carriers(&token).into_iter().filter(|&pid| running(pid)).collect();
        assert!(after.is_empty(), "still running: {after:?}");
        assert!(!p.escaped().killed.is_empty(), "the escaped sleeper was found: {:?}", p.escaped());
        assert!(p.escaped().alive.is_empty());
    }
}

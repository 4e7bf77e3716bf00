//! An external method's process: started in a process group of its own, spoken to line by line
//! with a timeout per request, its stderr logged and its last lines kept for error messages, and
//! killed with everything it started when dropped.
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

    /// Kill the program and everything in its process group, reap it, and let the stderr reader
    /// finish the log (briefly: a process outside the group may hold the pipe).
    pub fn kill(&mut self) {
        if self.killed {
            return;
        }
        self.requests = None;
        kill_group(self.child.id());
        let _ = self.child.wait();
        self.killed = true;
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

fn keep_stderr(stderr: impl Read, mut log: Option<std::fs::File>, tail: &Mutex<StderrTail>) {
    let mut reader = BufReader::new(stderr);
    let mut bytes = Vec::new();
    loop {
        bytes.clear();
        match reader.read_until(b'\n', &mut bytes) {
            Ok(0) | Err(_) => return,
            Ok(_) => {
                if let Some(file) = &mut log {
                    let _ = file.write_all(&bytes);
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

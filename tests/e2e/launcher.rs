//! Starts and stops the virtual robot binary for the integration tests (included with
//! `#[path]` by tests/pymycobot*.rs).

use std::io::{BufRead, BufReader, Write};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::mpsc;
use std::thread;
use std::time::{Duration, Instant};

use nix::sys::signal::{Signal, kill};
use nix::unistd::Pid;

/// Longest the robot may take to print its banner.
const START_DEADLINE: Duration = Duration::from_secs(20);
/// Longest the robot may take to exit after a stop signal.
const STOP_DEADLINE: Duration = Duration::from_secs(5);

/// A running robot and the banner it printed up to "ready".
pub struct Launched {
    pub child: Child,
    pub banner: String,
    /// The lines it printed after the banner, as they come.
    lines: mpsc::Receiver<String>,
}

impl Launched {
    /// The value of the banner line starting with `prefix`, e.g. "tcp on ".
    pub fn banner_value(&self, prefix: &str) -> Option<&str> {
        self.banner
            .lines()
            .find_map(|line| line.strip_prefix(prefix))
    }

    /// The lines the robot printed after "ready" so far (collisions, port moves).
    #[allow(
        dead_code,
        reason = "only some of the test crates that include this file read them"
    )]
    pub fn printed_after_ready(&self) -> Vec<String> {
        self.lines.try_iter().collect()
    }

    /// Types `keys` on the robot's standard input (a pipe kept open while it runs).
    #[allow(
        dead_code,
        reason = "only some of the test crates that include this file type keys"
    )]
    pub fn type_keys(&mut self, keys: &str) {
        let stdin = self.child.stdin.as_mut().expect("piped stdin");
        stdin
            .write_all(keys.as_bytes())
            .expect("type on the robot's stdin");
        stdin.flush().expect("flush the robot's stdin");
    }

    /// Sends `signal` and waits for the exit; kills the robot and returns None if it hangs.
    pub fn stop_with(&mut self, signal: Signal) -> Option<ExitStatus> {
        let pid = Pid::from_raw(i32::try_from(self.child.id()).ok()?);
        let _ = kill(pid, signal);
        let deadline = Instant::now() + STOP_DEADLINE;
        while Instant::now() < deadline {
            if let Ok(Some(status)) = self.child.try_wait() {
                return Some(status);
            }
            // Often enough that a test which times the exit reads it to a few milliseconds.
            thread::sleep(Duration::from_millis(2));
        }
        let _ = self.child.kill();
        let _ = self.child.wait();
        None
    }
}

impl Drop for Launched {
    fn drop(&mut self) {
        if matches!(self.child.try_wait(), Ok(None)) {
            self.stop_with(Signal::SIGTERM);
        }
    }
}

/// Starts the robot binary with `args` and waits for its "ready" line. Its stdout keeps being
/// drained afterwards, so the robot never blocks on (or fails writing to) a full pipe; the
/// lines are kept for [`Launched::printed_after_ready`]. Its stdin is a pipe the test holds
/// ([`Launched::type_keys`]), never the terminal the tests run in.
pub fn launch(args: &[&str]) -> Launched {
    let mut child = Command::new(env!("CARGO_BIN_EXE_open-mycobot"))
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .expect("start the virtual robot");
    let stdout = child.stdout.take().expect("piped stdout");
    let (lines_tx, lines) = mpsc::channel();
    thread::spawn(move || {
        for line in BufReader::new(stdout).lines() {
            let Ok(line) = line else { break };
            let _ = lines_tx.send(line);
        }
    });
    let mut banner = String::new();
    let deadline = Instant::now() + START_DEADLINE;
    loop {
        let left = deadline.saturating_duration_since(Instant::now());
        match lines.recv_timeout(left) {
            Ok(line) => {
                banner.push_str(&line);
                banner.push('\n');
                if line.starts_with("ready") {
                    return Launched {
                        child,
                        banner,
                        lines,
                    };
                }
            }
            Err(e) => {
                let _ = child.kill();
                let _ = child.wait();
                panic!("the robot did not get ready ({e:?}); it printed:\n{banner}");
            }
        }
    }
}

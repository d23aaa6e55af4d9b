//! A virtual robot for a Python suite of tests/e2e, and the run of that suite with a deadline
//! (included with `#[path]` by tests/pymycobot.rs and tests/pymycobot_298.rs, beside
//! `launcher.rs` and `venv.rs`).

use std::fs;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::thread;
use std::time::{Duration, Instant};

use super::launcher::{Launched, launch};
use super::venv::workspace;

/// A Python suite must finish within this (it runs in real time; the largest, ~2 min).
pub const SUITE_DEADLINE: Duration = Duration::from_secs(360);

/// The robot for a suite: a pty link in the temp dir, TCP and the view on free ports.
pub struct Robot {
    pub launched: Launched,
    pub link: PathBuf,
    pub tcp: String,
    /// The view's `host:port`.
    pub view: String,
    /// The dialect its Basic speaks, as its banner names it (`pymycobot`, `seed`).
    pub dialect: String,
}

impl Robot {
    /// A robot of its own named `name` (its pty link and flash file carry the name, so the
    /// tests of a file, which run at the same time, each talk to their own), with `extra`
    /// arguments on its command line.
    pub fn start(name: &str, extra: &[&str]) -> Robot {
        let link =
            std::env::temp_dir().join(format!("open-mycobot-e2e-{}-{name}", std::process::id()));
        let link_arg = link.to_str().expect("temp dir path is UTF-8");
        // The Basic's flash (Wi-Fi settings the suite changes, the dialect) in a scratch
        // file, erased.
        let flash =
            Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("e2e-basic-flash-{name}.bin"));
        let _ = fs::remove_file(&flash);
        let flash_arg = flash.to_str().expect("target dir path is UTF-8");
        // The view on too: the suite runs with the simulation publishing (and may read it).
        let mut args = vec![
            "--pty-link",
            link_arg,
            "--tcp",
            "127.0.0.1:0",
            "--web",
            "127.0.0.1:0",
            "--basic-flash",
            flash_arg,
        ];
        args.extend_from_slice(extra);
        let launched = launch(&args);
        let value = |prefix: &str| {
            launched
                .banner_value(prefix)
                .unwrap_or_else(|| panic!("no {prefix:?} in the banner:\n{}", launched.banner))
                .to_string()
        };
        let tcp = value("tcp on ");
        let first_word = |prefix: &str| {
            value(prefix)
                .split_whitespace()
                .next()
                .unwrap_or_default()
                .to_string()
        };
        let view = first_word("view on http://");
        let dialect = first_word("protocol ");
        Robot {
            launched,
            link,
            tcp,
            view,
            dialect,
        }
    }
}

/// Runs `python -m unittest` on the modules of tests/e2e named like `pattern` (e.g.
/// `test_*.py`) with a deadline; returns (success, output). The suite finds the robot in its
/// environment: `MYCOBOT_PORT` (the pty link), `MYCOBOT_TCP`, `MYCOBOT_VIEW` (the view's
/// `host:port`) and `MYCOBOT_DIALECT` (what the robot's Basic speaks).
pub fn run_suite(python: &Path, robot: &Robot, pattern: &str) -> (bool, String) {
    let e2e = workspace().join("tests/e2e");
    let mut child = Command::new(python)
        .args(["-m", "unittest", "discover", "-v", "-s"])
        .arg(&e2e)
        .arg("-t")
        .arg(&e2e)
        .args(["-p", pattern])
        .env("MYCOBOT_PORT", &robot.link)
        .env("MYCOBOT_TCP", &robot.tcp)
        .env("MYCOBOT_VIEW", &robot.view)
        .env("MYCOBOT_DIALECT", &robot.dialect)
        // Started just now: its start-up state is checked, not only reset.
        .env("MYCOBOT_FRESH", "1")
        .env("PYTHONDONTWRITEBYTECODE", "1")
        .env("PYTHONWARNINGS", "ignore::DeprecationWarning")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start the Python suite");
    let mut stdout = child.stdout.take().expect("piped stdout");
    let mut stderr = child.stderr.take().expect("piped stderr");
    let out = thread::spawn(move || {
        let mut s = String::new();
        let _ = stdout.read_to_string(&mut s);
        s
    });
    let err = thread::spawn(move || {
        let mut s = String::new();
        let _ = stderr.read_to_string(&mut s);
        s
    });
    let deadline = Instant::now() + SUITE_DEADLINE;
    let status = loop {
        match child.try_wait() {
            Ok(Some(status)) => break Some(status),
            Ok(None) if Instant::now() < deadline => thread::sleep(Duration::from_millis(100)),
            _ => {
                let _ = child.kill();
                let _ = child.wait();
                break None;
            }
        }
    };
    let output = format!(
        "{}{}",
        out.join().unwrap_or_default(),
        err.join().unwrap_or_default()
    );
    match status {
        Some(status) => (status.success(), output),
        None => (
            false,
            format!("suite killed after {SUITE_DEADLINE:?}\n{output}"),
        ),
    }
}

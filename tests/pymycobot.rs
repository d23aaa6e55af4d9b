//! `cargo test` runs the Python end-to-end suite (tests/e2e/) with the real client, pymycobot
//! 4.0.7, against the real binary: the virtual robot in real time on a pseudo-terminal and TCP.
//!
//! The interpreter is `$MYCOBOT_PYTHON`, else the workspace's `.venv/bin/python`; on a fresh
//! clone the venv is created (`python3 -m venv .venv && pip install pymycobot==4.0.7`) under a
//! file lock, so parallel test binaries do not race. Nothing is skipped silently: a missing
//! Python or a failed install fails the test with the reason.

use std::fs::{self, File};
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::thread;
use std::time::{Duration, Instant};

use nix::sys::signal::Signal;

#[path = "e2e/launcher.rs"]
mod launcher;
use launcher::{Launched, launch};

const PYMYCOBOT: &str = "pymycobot==4.0.7";
/// The whole Python suite must finish within this (it runs in real time; ~2 min expected).
const SUITE_DEADLINE: Duration = Duration::from_secs(360);

fn workspace() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The Python to run the suite with; creates the workspace venv if needed.
fn python() -> PathBuf {
    if let Some(explicit) = std::env::var_os("MYCOBOT_PYTHON") {
        return PathBuf::from(explicit);
    }
    let root = workspace();
    let python = root.join(".venv/bin/python");
    let lock = File::create(Path::new(env!("CARGO_TARGET_TMPDIR")).join("venv.lock"))
        .expect("create the venv lock file");
    lock.lock().expect("lock the venv lock file");
    if !imports_pymycobot(&python) {
        if !python.exists() {
            run_checked(
                Command::new("python3")
                    .args(["-m", "venv"])
                    .arg(root.join(".venv")),
            );
        }
        run_checked(
            Command::new(root.join(".venv/bin/pip")).args(["install", "--quiet", PYMYCOBOT]),
        );
        assert!(
            imports_pymycobot(&python),
            "pymycobot still not importable after installing it into {}",
            python.display()
        );
    }
    python
}

fn imports_pymycobot(python: &Path) -> bool {
    Command::new(python)
        .args(["-c", "import pymycobot, serial"])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

fn run_checked(command: &mut Command) {
    let output = command
        .output()
        .unwrap_or_else(|e| panic!("cannot run {command:?}: {e}"));
    assert!(
        output.status.success(),
        "{command:?} failed:\n{}{}",
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
}

/// The robot for the suite: a pty link in the temp dir, TCP on a free port.
struct Robot {
    launched: Launched,
    link: PathBuf,
    tcp: String,
}

impl Robot {
    fn start() -> Robot {
        let link = std::env::temp_dir().join(format!("open-mycobot-e2e-{}", std::process::id()));
        let link_arg = link.to_str().expect("temp dir path is UTF-8");
        let launched = launch(&["--pty-link", link_arg, "--tcp", "127.0.0.1:0"]);
        let tcp = launched
            .banner_value("tcp on ")
            .unwrap_or_else(|| panic!("no TCP address in the banner:\n{}", launched.banner))
            .to_string();
        Robot {
            launched,
            link,
            tcp,
        }
    }
}

/// Runs `python -m unittest` on tests/e2e with a deadline; returns (success, output).
fn run_suite(python: &Path, robot: &Robot) -> (bool, String) {
    let e2e = workspace().join("tests/e2e");
    let mut child = Command::new(python)
        .args(["-m", "unittest", "discover", "-v", "-s"])
        .arg(&e2e)
        .arg("-t")
        .arg(&e2e)
        .env("MYCOBOT_PORT", &robot.link)
        .env("MYCOBOT_TCP", &robot.tcp)
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

#[test]
fn pymycobot_end_to_end_suite() {
    let python = python();
    let mut robot = Robot::start();
    assert!(
        fs::read_link(&robot.link).is_ok(),
        "--pty-link did not create {}",
        robot.link.display()
    );

    let (passed, output) = run_suite(&python, &robot);

    let exit = robot.launched.stop_with(Signal::SIGTERM);
    let link_left = fs::symlink_metadata(&robot.link).is_ok();
    assert!(passed, "pymycobot end-to-end suite failed:\n{output}");
    println!("{output}");
    assert!(
        exit.is_some_and(|s| s.success()),
        "the robot did not stop cleanly on SIGTERM: {exit:?}"
    );
    assert!(!link_left, "the pty symlink was not removed on exit");
}

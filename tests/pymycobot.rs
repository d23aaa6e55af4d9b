//! `cargo test` runs the Python end-to-end suite (tests/e2e/) with the real client, pymycobot
//! 4.0.7, against the real binary: the virtual robot in real time on a pseudo-terminal and TCP.
//! The interpreter is the one `e2e/venv.rs` finds or sets up.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)] // a test harness: a panic is a failed check

use std::fs;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::thread;
use std::time::{Duration, Instant};

use nix::sys::signal::Signal;

#[path = "e2e/launcher.rs"]
mod launcher;
use launcher::{Launched, launch};
#[path = "e2e/venv.rs"]
mod venv;
use venv::{Shown, python, set_up, workspace};

/// The whole Python suite must finish within this (it runs in real time; ~2 min expected).
const SUITE_DEADLINE: Duration = Duration::from_secs(360);

/// The robot for the suite: a pty link in the temp dir, TCP and the view on free ports.
struct Robot {
    launched: Launched,
    link: PathBuf,
    tcp: String,
}

impl Robot {
    /// A robot of its own named `name` (its pty link and flash file carry the name, so the
    /// tests of this file, which run at the same time, each talk to their own), with `extra`
    /// arguments on its command line.
    fn start(name: &str, extra: &[&str]) -> Robot {
        let link =
            std::env::temp_dir().join(format!("open-mycobot-e2e-{}-{name}", std::process::id()));
        let link_arg = link.to_str().expect("temp dir path is UTF-8");
        // The Basic's flash (Wi-Fi settings the suite changes) in a scratch file, erased.
        let flash =
            Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("e2e-basic-flash-{name}.bin"));
        let _ = fs::remove_file(&flash);
        let flash_arg = flash.to_str().expect("target dir path is UTF-8");
        // The view on too (nobody watches it): the suite runs with the simulation publishing.
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

/// Runs `python -m unittest` on the modules of tests/e2e named like `pattern` (e.g.
/// `test_*.py`) with a deadline; returns (success, output).
fn run_suite(python: &Path, robot: &Robot, pattern: &str) -> (bool, String) {
    let e2e = workspace().join("tests/e2e");
    let mut child = Command::new(python)
        .args(["-m", "unittest", "discover", "-v", "-s"])
        .arg(&e2e)
        .arg("-t")
        .arg(&e2e)
        .args(["-p", pattern])
        .env("MYCOBOT_PORT", &robot.link)
        .env("MYCOBOT_TCP", &robot.tcp)
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

#[test]
fn pymycobot_end_to_end_suite() {
    let python = python();
    let mut robot = Robot::start("suite", &[]);
    assert!(
        fs::read_link(&robot.link).is_ok(),
        "--pty-link did not create {}",
        robot.link.display()
    );

    let (passed, output) = run_suite(&python, &robot, "test_*.py");

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

/// Collision protection with pymycobot against a robot with obstacles in joint 2's way at 30
/// degrees and joint 3's at -40 (tests/e2e/obstacle_suite.py); the robot announces the
/// obstacles and prints the collisions it detects.
#[test]
fn pymycobot_against_an_obstacle() {
    let python = python();
    let mut robot = Robot::start("obstacle", &["--obstacle", "2:30", "--obstacle", "3:-40"]);
    let obstacles: Vec<&str> = robot
        .launched
        .banner
        .lines()
        .filter_map(|line| line.strip_prefix("obstacle: "))
        .collect();
    assert_eq!(obstacles, ["joint 2 at 30.00 deg", "joint 3 at -40.00 deg"]);
    let (passed, output) = run_suite(&python, &robot, "obstacle_*.py");
    robot.launched.stop_with(Signal::SIGTERM);
    let printed = robot.launched.printed_after_ready();
    assert!(passed, "obstacle suite failed:\n{output}");
    println!("{output}");
    assert!(
        printed
            .iter()
            .any(|line| line.starts_with("collision: joint 2 while moving joints, error 16")),
        "the robot printed no collision: {printed:?}"
    );
}

#[test]
fn an_unreachable_package_index_is_one_clear_message() {
    // A venv of its own (kept between runs: it never gets the client), and an index nobody
    // serves, so pip fails at once.
    let venv = Path::new(env!("CARGO_TARGET_TMPDIR")).join("venv-no-index");
    let offline = ["--index-url", "http://127.0.0.1:9/", "--retries", "0"];
    let why = set_up(&venv, &offline, Shown::No).expect_err("installed without an index");
    assert!(
        why.starts_with("pip could not install pymycobot==4.0.7 into ")
            && why.contains("\nIs PyPI reachable from this machine?"),
        "{why}"
    );
}

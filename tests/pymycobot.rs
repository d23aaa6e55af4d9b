//! `cargo test` runs the Python end-to-end suite (tests/e2e/) with the real client, pymycobot
//! 4.0.7, against the real binary: the virtual robot in real time on a pseudo-terminal and TCP.
//! The interpreter is the one `e2e/venv.rs` finds or sets up.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)] // a test harness: a panic is a failed check

use std::fs;
use std::path::Path;

use nix::sys::signal::Signal;

#[path = "e2e/launcher.rs"]
mod launcher;
#[path = "e2e/suite.rs"]
mod suite;
use suite::{Robot, run_suite};
#[path = "e2e/venv.rs"]
mod venv;
use venv::{Shown, python, set_up};

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

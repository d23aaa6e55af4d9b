//! pymycobot 2.9.8's `MyCobot` class, unchanged, against the virtual robot: a plain script's
//! calls (tests/e2e/seed_298_suite.py) all come out right in the seed dialect, and the same
//! calls go wrong in the pymycobot dialect, whose status replies 2.9.8 never reads. The
//! interpreter is 2.9.8's venv (`.venv-298`), which `e2e/venv.rs` finds or sets up.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)] // a test harness: a panic is a failed check

use nix::sys::signal::Signal;

#[path = "e2e/launcher.rs"]
mod launcher;
#[path = "e2e/suite.rs"]
mod suite;
use suite::{Robot, run_suite};
#[path = "e2e/venv.rs"]
mod venv;
use venv::{Client, python_for};

/// The suite's file in tests/e2e.
const SUITE: &str = "seed_298_suite.py";

/// Runs the suite against a robot of its own speaking `dialect`; panics unless it passed and
/// every test named in `must_pass` ran and passed (the others skip themselves: they are for
/// the other dialect).
fn run_against(dialect: &str, must_pass: &[&str]) -> String {
    let python = python_for(Client::V298);
    let mut robot = Robot::start(&format!("298-{dialect}"), &["--dialect", dialect]);
    assert_eq!(robot.dialect, dialect, "banner:\n{}", robot.launched.banner);
    let (passed, output) = run_suite(&python, &robot, SUITE);
    robot.launched.stop_with(Signal::SIGTERM);
    assert!(
        passed,
        "pymycobot 2.9.8 in the {dialect} dialect failed:\n{output}"
    );
    for test in must_pass {
        assert!(
            passed_in(&output, test),
            "{test} did not run and pass in the {dialect} dialect:\n{output}"
        );
    }
    output
}

/// True if unittest's verbose output says `test` passed: its line `name (module.Class.name)`,
/// then ` ... ok` on it or, after a docstring's first line, on the next.
fn passed_in(output: &str, test: &str) -> bool {
    let start = format!("{test} (");
    output
        .lines()
        .skip_while(|line| !line.starts_with(&start))
        .find(|line| line.contains(" ... "))
        .is_some_and(|line| line.ends_with(" ... ok"))
}

#[test]
fn pymycobot_2_9_8_is_right_in_the_seed_dialect() {
    let output = run_against(
        "seed",
        &[
            "test_power_off_and_on",
            "test_get_angles_get_coords_and_send_angles",
            "test_send_angle_numbers_joints_from_0",
            "test_is_moving_during_and_after_a_move",
            "test_send_coords_joint_and_linear",
            "test_send_coord_moves_x_y_and_z",
            "test_set_color_lights_the_led",
            "test_gripper",
            "test_pause_holds_the_arm",
            "test_stop_stops_a_move",
            "test_release_all_servos_then_power_on",
            "test_2_9_8_calls_that_mean_otherwise",
            "test_set_commands_get_no_reply",
        ],
    );
    println!("{output}");
}

#[test]
fn pymycobot_2_9_8_reads_the_wrong_replies_in_the_pymycobot_dialect() {
    let output = run_against(
        "pymycobot",
        &["test_unread_status_frames_corrupt_the_next_reads"],
    );
    println!("{output}");
}

//! The Basic's teach-and-play program (`firmware_basic::teach`, the board image `basic-teach`)
//! as an owner uses it: press A, move the arm by hand through the simulated servos, press A
//! to end, press B, and the arm repeats the path; C stops a playback. In both dialects.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)] // a test harness: a panic is a failed check

mod sim_support;

use firmware_basic::Buttons;
use firmware_basic::teach::{Activity, SAMPLE_PERIOD_US};
use open_mycobot::sim::{BasicProgram, RobotConfig, VirtualRobot};
use protocol_core::command::{Reply, Request};
use protocol_core::dialect::Dialect;
use sim_support::*;

/// How often the test looks at the arm, in us.
const LOOK_US: u64 = 10_000;

fn teach_arm(dialect: Dialect) -> VirtualRobot {
    let mut config = RobotConfig {
        basic_program: Some(BasicProgram::Teach),
        ..RobotConfig::default()
    };
    config.basic.dialect = Some(dialect);
    booted(config)
}

fn activity(robot: &VirtualRobot) -> Activity {
    robot.teach_status().expect("the Basic runs teach").activity
}

/// Presses and releases a button as a finger does: 150 ms down.
fn press(robot: &mut VirtualRobot, which: fn(&mut Buttons)) {
    let io = robot.basic_io_mut().expect("a Basic");
    which(&mut io.buttons);
    robot.run_for(150_000);
    robot.basic_io_mut().expect("a Basic").buttons = Buttons::default();
    robot.run_for(50_000);
}

fn a(b: &mut Buttons) {
    b.a = true;
}
fn b(b: &mut Buttons) {
    b.b = true;
}
fn c(b: &mut Buttons) {
    b.c = true;
}

/// Runs for `dt_us`, noting the arm's true joint angles every [`LOOK_US`].
fn watch(robot: &mut VirtualRobot, dt_us: u64, seen: &mut Vec<[f64; 6]>) {
    let end = robot.now_us() + dt_us;
    while robot.now_us() < end {
        robot.run_for(LOOK_US);
        seen.push(robot.shaft_angles_deg());
    }
}

/// The largest joint difference between `p` and `q`, degrees.
fn apart(p: &[f64; 6], q: &[f64; 6]) -> f64 {
    p.iter()
        .zip(q)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max)
}

/// How far `p` is from the nearest of `path`'s points, degrees.
fn off_path(p: &[f64; 6], path: &[[f64; 6]]) -> f64 {
    path.iter()
        .map(|q| apart(p, q))
        .fold(f64::INFINITY, f64::min)
}

/// Records a hand move in `dialect` and returns the arm's path while the hand moved it.
fn record_a_hand_move(robot: &mut VirtualRobot) -> Vec<[f64; 6]> {
    press(robot, a);
    assert_eq!(activity(robot), Activity::Recording);
    let mut hand = vec![robot.shaft_angles_deg()];
    // Joint 1 by +35 deg and joint 2 by -26 deg together, then joint 3 by +18 deg.
    assert!(robot.turn_by_hand(1, 2048 + 400, 2_000_000));
    assert!(robot.turn_by_hand(2, 2048 - 300, 2_000_000));
    watch(robot, 2_200_000, &mut hand);
    assert!(robot.turn_by_hand(3, 2048 + 200, 1_000_000));
    watch(robot, 1_300_000, &mut hand);
    press(robot, a);
    robot.run_for(200_000);
    assert_eq!(activity(robot), Activity::Idle, "the record ended");
    let status = robot.teach_status().unwrap();
    assert_eq!(status.error, None);
    // 20 points a second for the 3.5 s and the presses.
    let expected = 3_500_000 / SAMPLE_PERIOD_US;
    let points = u64::from(status.points);
    assert!(
        (expected..expected + 12).contains(&points),
        "{points} points recorded"
    );
    hand
}

/// Plays the record back and returns the arm's path from the moment it set off along it.
fn play_back(robot: &mut VirtualRobot) -> Vec<[f64; 6]> {
    press(robot, b);
    let mut seen = Vec::new();
    let mut along = Vec::new();
    let start = robot.now_us();
    while activity(robot) != Activity::Idle {
        assert!(robot.now_us() - start < MOTION_TIMEOUT_US, "still playing");
        seen.clear();
        watch(robot, LOOK_US, &mut seen);
        if matches!(activity(robot), Activity::Playing | Activity::Settling) {
            along.append(&mut seen);
        }
    }
    let status = robot.teach_status().unwrap();
    assert_eq!(status.error, None, "the playback ended early");
    assert_eq!(status.plays, 1);
    along
}

fn repeats_a_hand_move_within_a_degree(dialect: Dialect) {
    let mut robot = teach_arm(dialect);
    let hand = record_a_hand_move(&mut robot);
    let end = *hand.last().unwrap();
    // Held where the hand left it.
    robot.run_for(1_000_000);
    assert!(apart(&robot.shaft_angles_deg(), &end) < 0.5, "held");

    let replay = play_back(&mut robot);
    assert!(replay.len() > 300, "{} looks along the path", replay.len());
    let worst = replay
        .iter()
        .map(|p| off_path(p, &hand))
        .fold(0.0, f64::max);
    assert!(worst <= 1.0, "the replay left the path by {worst:.2} deg");
    // Every point of the hand's path was passed, in the replay, within a degree.
    let missed = hand
        .iter()
        .map(|p| off_path(p, &replay))
        .fold(0.0, f64::max);
    assert!(
        missed <= 1.0,
        "a point of the path was missed by {missed:.2} deg"
    );
    let rest = robot.shaft_angles_deg();
    assert!(
        apart(&rest, &end) <= 0.5,
        "at rest {rest:?}, the hand left {end:?}"
    );
    // And at rest: nothing moves once the playback is done.
    robot.run_for(1_000_000);
    assert!(apart(&robot.shaft_angles_deg(), &rest) <= 0.1);
}

#[test]
fn the_arm_repeats_a_path_taught_by_hand_within_a_degree() {
    repeats_a_hand_move_within_a_degree(Dialect::Pymycobot);
}

#[test]
fn the_arm_repeats_a_path_taught_by_hand_in_the_seed_dialect_too() {
    repeats_a_hand_move_within_a_degree(Dialect::Seed);
}

#[test]
fn c_stops_a_playback_where_the_arm_is() {
    let mut robot = teach_arm(Dialect::Pymycobot);
    let hand = record_a_hand_move(&mut robot);
    press(&mut robot, b);
    // Along the path for a while, then C.
    let start = robot.now_us();
    while activity(&robot) != Activity::Playing {
        assert!(robot.now_us() - start < MOTION_TIMEOUT_US, "never played");
        robot.run_for(LOOK_US);
    }
    robot.run_for(1_000_000);
    press(&mut robot, c);
    assert_eq!(activity(&robot), Activity::Idle);
    robot.run_for(500_000);
    let stopped = robot.shaft_angles_deg();
    robot.run_for(1_000_000);
    assert!(
        apart(&robot.shaft_angles_deg(), &stopped) <= 0.5,
        "moved on after C"
    );
    assert!(
        apart(&stopped, hand.last().unwrap()) > 5.0,
        "stopped half way, not at the end"
    );
}

#[test]
fn the_usb_link_still_answers_while_the_program_runs() {
    let mut robot = teach_arm(Dialect::Pymycobot);
    press(&mut robot, a);
    assert!(robot.turn_by_hand(1, 2048 + 300, 1_000_000));
    robot.run_for(500_000);
    // A PC watches the hand move through the transponder.
    let angles = get_angles(&mut robot);
    assert!(angles[0].0 > 100, "joint 1 read {angles:?}");
    robot.run_for(700_000);
    press(&mut robot, a);
    let status = robot.teach_status().unwrap();
    assert_eq!((status.activity, status.error), (Activity::Idle, None));
    assert!(status.points > 20);
    // And the arm holds again.
    assert_eq!(ask(&mut robot, Request::IsPowerOn), Reply::Byte(1));
}

#[test]
fn buttons_do_nothing_without_a_record_and_a_button_held_from_power_up_waits_for_release() {
    let mut robot = teach_arm(Dialect::Pymycobot);
    // B without a record: nothing to play.
    press(&mut robot, b);
    assert_eq!(activity(&robot), Activity::Idle);
    // A held from power-up: no record until it is let go and pressed again.
    let mut config = RobotConfig {
        basic_program: Some(BasicProgram::Teach),
        ..RobotConfig::default()
    };
    config.basic.dialect = Some(Dialect::Pymycobot);
    let mut robot = VirtualRobot::new(config);
    robot.basic_io_mut().unwrap().buttons.a = true;
    robot.run_for(CLIENT_OPEN_DELAY_US);
    assert_eq!(activity(&robot), Activity::Idle);
    robot.basic_io_mut().unwrap().buttons.a = false;
    robot.run_for(100_000);
    press(&mut robot, a);
    assert_eq!(activity(&robot), Activity::Recording);
}

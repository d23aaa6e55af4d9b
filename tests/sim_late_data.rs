//! Servo replies that come late or not at all, as on a busy bus or with a slow Atom (issue 27:
//! an emulated ESP32 ran lines 5.7 to 371 mm off their line and let joints run on to their
//! limits while reporting success). The Atom may not know where a joint is; it must never
//! guess: a line stays on its line or stops with an error, a finished move stays finished, a
//! joint whose replies stop stops the motion with its code for 0x07, "is moving" never says
//! no about a joint it has no fresh reading of, and a stop never turns a joint back.
//!
//! An answer that comes late but whole is still a reading (the Atom takes it for up to
//! `LATE_ANSWER_WINDOW_US` after its deadline, dated when it was asked for): a joint answering
//! a few hundred microseconds late keeps its motion going. One later than that is lost.
//!
//! The faults are the simulated servos' ([`Faults::reply_delay_us`]: each answer late, still
//! on the wire when it comes; [`Faults::dropped_per_mille`] and
//! [`SimServo::drop_next_answers`]: answers lost), and a slow Atom
//! ([`RobotConfig::atom_loop_us`]: it reads its UART only once a loop).
//!
//! [`SimServo::drop_next_answers`]: open_mycobot::sim::SimServo::drop_next_answers
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)] // a test harness: a panic is a failed check

mod sim_support;

use open_mycobot::sim::measure;
use open_mycobot::sim::{Faults, RobotConfig, VirtualRobot};
use protocol_core::command::{MoveMode, Pose, Reply, Request};
use protocol_core::units::DeciMm;
use sim_support::*;

/// Where the lines start: away from the singularities.
const LINE_START_DEG: [f64; 6] = [10.0, -30.0, -50.0, -10.0, 10.0, 20.0];

/// The 0x07 code of a joint whose readings stopped or jumped: 20 + its number.
fn state_lost(joint: u8) -> Reply {
    Reply::Byte(20 + joint)
}

fn error_info(robot: &mut VirtualRobot) -> u8 {
    match ask(robot, Request::GetErrorInfo) {
        Reply::Byte(code) => code,
        other => panic!("get_error_information answered {other:?}"),
    }
}

fn is_moving(robot: &mut VirtualRobot) -> bool {
    ask(robot, Request::IsMoving) == Reply::Byte(1)
}

/// Sends angles (degrees) at `percent` and checks they are taken.
fn send_angles(robot: &mut VirtualRobot, angles: [f64; 6], percent: u8) {
    ack(
        robot,
        Request::SendAngles {
            angles: degrees(angles),
            speed: speed(percent),
        },
    );
}

/// Gives servo `id` `faults` (replacing its others).
fn set_faults(robot: &mut VirtualRobot, id: u8, faults: Faults) {
    robot.servo_mut(id).expect("servo").set_faults(faults);
}

/// A robot whose Atom runs its loop every `loop_us` (0: at once), booted.
fn robot_with_loop(loop_us: u64) -> VirtualRobot {
    booted(RobotConfig {
        atom_loop_us: loop_us,
        ..RobotConfig::default()
    })
}

/// Largest joint turn between two shaft readings, degrees.
fn largest_turn(a: &[f64; 6], b: &[f64; 6]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// What became of a straight line run with a fault.
#[derive(Debug)]
struct LineRun {
    /// The flange's largest distance from the segment, mm, until the arm was at rest.
    off_mm: f64,
    /// Whether the flange reached the line's end (within 2 mm).
    reached: bool,
    /// 0x07 at the end.
    error: u8,
    /// The most any joint turned in the second after "is moving" first said 0 (or after the
    /// end of the watch if it never did), degrees.
    moved_after_done: f64,
}

/// Moves to [`LINE_START_DEG`], then runs a line of (-60, 80, -40) mm at speed 50 while
/// `fault` acts every 0.5 ms (given the time since the line's request), watching the flange
/// for 4 s and asking "is moving" every 10 ms.
fn line_with(loop_us: u64, mut fault: impl FnMut(&mut VirtualRobot, u64)) -> LineRun {
    let mut robot = robot_with_loop(loop_us);
    send_angles(&mut robot, LINE_START_DEG, 100);
    wait_until_stopped(&mut robot);
    robot.run_for(300_000);
    let start = measure::flange(&robot.shaft_angles_deg());
    let Reply::Coords(from) = ask(&mut robot, Request::GetCoords) else {
        panic!("get_coords");
    };
    let to = Pose {
        x: DeciMm(from.x.0 - 600),
        y: DeciMm(from.y.0 + 800),
        z: DeciMm(from.z.0 - 400),
        ..from
    };
    let end = [to.x.0, to.y.0, to.z.0].map(|v| f64::from(v) / 10.0);
    ack(
        &mut robot,
        Request::SendCoords {
            pose: to,
            speed: speed(50),
            mode: Some(MoveMode::Linear),
        },
    );
    let t0 = robot.now_us();
    let mut off_mm: f64 = 0.0;
    let mut done_at: Option<[f64; 6]> = None;
    let mut moved_after_done: f64 = 0.0;
    for step in 0..8_000u64 {
        robot.run_for(500);
        let t = robot.now_us() - t0;
        fault(&mut robot, t);
        let shafts = robot.shaft_angles_deg();
        let p = measure::flange(&shafts);
        off_mm = off_mm.max(measure::distance_to_segment_mm(
            &p.position_mm,
            &start.position_mm,
            &end,
        ));
        match done_at {
            Some(at) => moved_after_done = moved_after_done.max(largest_turn(&at, &shafts)),
            None if step % 20 == 0 && !is_moving(&mut robot) => done_at = Some(shafts),
            None => {}
        }
        if done_at.is_some() && t > 4_000_000 {
            break;
        }
    }
    if done_at.is_none() {
        // Never reported still: the arm must be at rest all the same, whatever it says.
        let at = robot.shaft_angles_deg();
        robot.run_for(1_000_000);
        moved_after_done = largest_turn(&at, &robot.shaft_angles_deg());
    }
    let last = measure::flange(&robot.shaft_angles_deg());
    let reached = measure::distance_mm(&last.position_mm, &end) <= 2.0;
    LineRun {
        off_mm,
        reached,
        error: error_info(&mut robot),
        moved_after_done,
    }
}

/// A line stays within 1 mm of its segment, and it either ends on its target or stops with
/// a joint's error; no joint runs on afterwards.
fn assert_line_safe(run: &LineRun, what: &str) {
    assert!(run.off_mm <= 1.0, "{what}: left its line: {run:?}");
    assert!(
        run.reached || (21..=26).contains(&run.error),
        "{what}: stopped short without saying why: {run:?}"
    );
    assert!(
        run.moved_after_done <= 0.5,
        "{what}: a joint ran on after the end: {run:?}"
    );
}

/// (a) Joint 3's answers come 300 us late from the middle of the line on (past the Atom's
/// deadline: every read of it times out, and the answer comes whole while the wire is still
/// the servo's). Before, joint 3 got no goal any more and stayed where it was: the flange went
/// 119 mm off the line, 0x07 at 0. Now the late answers are readings: the line goes on along
/// its line to its target.
#[test]
fn a_line_whose_joint_answers_late_stays_on_its_line_to_its_target() {
    let run = line_with(0, |robot, t| {
        if (500_000..501_000).contains(&t) {
            set_faults(robot, 3, Faults::late_replies(300));
        }
    });
    assert_line_safe(&run, "joint 3 late");
    assert!(run.reached, "{run:?}");
    assert_eq!(run.error, 0, "{run:?}");
}

/// (a) Joint 3's answers come 8 ms late from the middle of the line on: past the window a
/// late answer is taken in (and into the Atom's next transactions on the wire). The line stops
/// along its line with joint 3's code.
#[test]
fn a_line_whose_joint_answers_far_too_late_stops_on_its_line_with_the_joints_code() {
    let run = line_with(0, |robot, t| {
        if (500_000..501_000).contains(&t) {
            set_faults(robot, 3, Faults::late_replies(8_000));
        }
    });
    assert_line_safe(&run, "joint 3 far too late");
    assert_eq!(run.error, 23, "{run:?}");
    assert!(!run.reached, "{run:?}");
}

/// (a) A slow Atom (its loop every 2 ms) whose joint 3 loses three answers in a row every
/// 30 ms. Before, joint 3 dropped out of the line's goals with a goal at its -150 deg limit
/// (a braking distance worked out for the 100 steps/s^2 its share of the line's acceleration
/// came to) and ran there: 145 mm off the line, "finished", 0x07 at 0.
#[test]
fn a_line_on_a_slow_atom_losing_answers_never_runs_a_joint_to_its_limit() {
    let run = line_with(2_000, |robot, t| {
        if t % 30_000 < 500 {
            robot.servo_mut(3).unwrap().drop_next_answers(3);
        }
    });
    assert_line_safe(&run, "slow Atom, joint 3 losing answers");
}

/// (a) Every joint loses a few answers now and then (three in a row every 100 ms, each joint
/// in turn): the reads come back in time, so the line goes on and ends on its target. Before,
/// a joint that missed three reads got no goals until it was read again, and the flange left
/// the line by up to 5.4 mm.
#[test]
fn a_line_whose_joints_lose_a_few_answers_ends_on_its_target() {
    for joint in 1..=6u8 {
        let run = line_with(0, |robot, t| {
            if t % 100_000 < 500 {
                robot.servo_mut(joint).unwrap().drop_next_answers(4);
            }
        });
        assert_line_safe(&run, &format!("joint {joint} losing answers"));
        assert!(run.reached && run.error == 0, "joint {joint}: {run:?}");
    }
}

/// (b) Once a move is reported finished no joint moves. A slow Atom (3 ms loop) whose joint 2
/// loses three answers every 30 ms: before, "is moving" said 0 at 2.45 s while joint 2 ran on
/// 54 deg to the goal it had been left with. Now the Atom, unable to read joint 2 often
/// enough, refuses to move (or stops), and says it is moving while joint 2 is unknown.
#[test]
fn a_move_reported_finished_stays_finished() {
    for (loop_us, joint) in [(3_000, 2u8), (2_000, 3), (1_000, 2)] {
        let run = line_with(loop_us, |robot, t| {
            if t % 30_000 < 500 {
                robot.servo_mut(joint).unwrap().drop_next_answers(3);
            }
        });
        assert!(
            run.moved_after_done <= 0.5,
            "loop {loop_us} us, joint {joint}: moved after the end: {run:?}"
        );
        assert!(run.off_mm <= 1.0, "{run:?}");
    }
}

/// (b) The same for a joint move whose goals two servos missed (a SYNC WRITE garbled where
/// they sit) while their answers were lost too, so the Atom could not see it (the C3 left two
/// joints at 0 with "is moving" 0). Before, the silent joints counted as arrived: "is moving"
/// said 0 with joints 2 and 5 still at 0, and once they answered again their goals were sent
/// again and they moved, with nobody told.
#[test]
fn send_angles_reported_finished_leaves_no_joint_behind() {
    for lost in [10u32, 30, 60] {
        let mut robot = arm();
        for id in [2, 5] {
            let servo = robot.servo_mut(id).unwrap();
            servo.lose_next_writes(1);
            servo.drop_next_answers(lost);
        }
        send_angles(&mut robot, [40.0, -30.0, 50.0, -40.0, 30.0, 60.0], 100);
        let t0 = robot.now_us();
        let mut done: Option<[f64; 6]> = None;
        let mut moved: f64 = 0.0;
        while robot.now_us() - t0 < 4_000_000 {
            robot.run_for(10_000);
            let shafts = robot.shaft_angles_deg();
            match done {
                Some(at) => moved = moved.max(largest_turn(&at, &shafts)),
                None if !is_moving(&mut robot) => done = Some(shafts),
                None => {}
            }
        }
        let done = done.expect("never reported finished");
        assert!(
            moved <= 0.5,
            "{lost} answers lost: a joint moved {moved:.2} deg after is_moving said 0 at {done:.1?}"
        );
    }
}

/// (c) Joint 2's answers stop (all lost) while joint 1 jogs: the jog stops within a fraction
/// of a second, every joint comes to rest, and 0x07 says 22. Before, the jog ran on with 0x07
/// at 0 (and joint 2 unwatched).
#[test]
fn a_joint_whose_replies_stop_stops_the_motion_with_its_code() {
    let mut robot = arm();
    jog_joint_1(&mut robot, 50);
    robot.run_for(300_000);
    set_faults(&mut robot, 2, Faults::dropped_replies(1000));
    robot.run_for(400_000);
    let at = robot.shaft_angles_deg();
    robot.run_for(500_000);
    assert!(
        largest_turn(&at, &robot.shaft_angles_deg()) <= 0.01,
        "still moving 0.4 s after joint 2 fell silent"
    );
    assert!(
        at[0] < 30.0,
        "joint 1 jogged on for long after joint 2 fell silent: {at:?}"
    );
    assert_eq!(ask(&mut robot, Request::GetErrorInfo), state_lost(2));
}

/// (c) The same through late answers: joint 5's replies come 8 ms late (each read times out,
/// the late answer comes past the window, into the Atom's next instructions) during a
/// send_angles.
#[test]
fn a_joint_answering_too_late_stops_the_move_with_its_code() {
    let mut robot = arm();
    send_angles(&mut robot, [90.0, 0.0, 0.0, 0.0, 90.0, 0.0], 30);
    robot.run_for(300_000);
    set_faults(&mut robot, 5, Faults::late_replies(8_000));
    robot.run_for(1_000_000);
    let at = robot.shaft_angles_deg();
    robot.run_for(500_000);
    assert!(largest_turn(&at, &robot.shaft_angles_deg()) <= 0.01);
    assert!(at[0] < 60.0, "the move went on: {at:?}");
    assert_eq!(ask(&mut robot, Request::GetErrorInfo), state_lost(5));
}

/// (c) Joint 5's replies 400 us late, but whole: readings, and the move ends on its target.
#[test]
fn a_joint_answering_late_but_whole_is_followed_to_the_target() {
    let mut robot = arm();
    send_angles(&mut robot, [90.0, 0.0, 0.0, 0.0, 90.0, 0.0], 30);
    robot.run_for(300_000);
    set_faults(&mut robot, 5, Faults::late_replies(400));
    wait_until_stopped(&mut robot);
    let at = robot.shaft_angles_deg();
    assert!(
        (at[0] - 90.0).abs() < 0.2 && (at[4] - 90.0).abs() < 0.2,
        "{at:?}"
    );
    assert_eq!(ask(&mut robot, Request::GetErrorInfo), Reply::Byte(0));
}

/// (d) "Is moving" says 1 while a joint has no fresh reading, at rest or not, and 0 again
/// once it is read. Before, a joint that did not answer was left out: 0 at once.
#[test]
fn is_moving_stays_1_while_a_joint_is_not_read() {
    let mut robot = arm();
    send_angles(&mut robot, [20.0, 0.0, 0.0, 0.0, 0.0, 0.0], 100);
    wait_until_stopped(&mut robot);
    set_faults(&mut robot, 4, Faults::dropped_replies(1000));
    robot.run_for(100_000);
    for _ in 0..10 {
        assert!(is_moving(&mut robot), "joint 4 unread, yet at rest?");
        robot.run_for(100_000);
    }
    set_faults(&mut robot, 4, Faults::NONE);
    robot.run_for(100_000);
    assert!(!is_moving(&mut robot), "read again: at rest");
    // And while a move is under way whose joint 4 stops answering.
    send_angles(&mut robot, [30.0, 0.0, 0.0, 10.0, 0.0, 0.0], 100);
    set_faults(&mut robot, 4, Faults::dropped_replies(1000));
    for _ in 0..10 {
        robot.run_for(100_000);
        assert!(
            is_moving(&mut robot),
            "joint 4 unread during a move, yet at rest?"
        );
    }
}

/// How far joint 1 turns back after `stop` at its furthest (degrees), with a slow Atom (its
/// loop every 3 ms) whose joint 1 loses `lost` answers in a row just before the stop, after
/// `command` ran for `run_us`. Checks that joint 1 was moving at the stop.
fn turned_back_after(command: Request, run_us: u64, lost: u32, stop: Request) -> f64 {
    let mut robot = robot_with_loop(3_000);
    ack(&mut robot, command);
    robot.run_for(run_us);
    let before = robot.shaft_angles_deg()[0];
    robot.servo_mut(1).unwrap().drop_next_answers(lost);
    robot.run_for(12_000);
    assert!(
        robot.shaft_angles_deg()[0] - before > 0.3,
        "joint 1 is not moving at the stop"
    );
    ack(&mut robot, stop);
    let mut furthest = f64::MIN;
    let mut back: f64 = 0.0;
    for _ in 0..1_500 {
        robot.run_for(1_000);
        let j1 = robot.shaft_angles_deg()[0];
        furthest = furthest.max(j1);
        back = back.max(furthest - j1);
    }
    back
}

/// (e) A stop brakes from where each joint was told to be, not from an old reading: joint 1
/// speeding up in a jog at full speed on a slow Atom, its last answers lost. Before, the
/// reading (taken at a lower speed, carried on for at most 20 ms at that speed) lay behind the
/// joint, and so did the stop's goal: joint 1 turned back by 3 deg (3.5 deg, once 12, on the
/// emulated ESP32).
#[test]
fn a_stop_never_turns_a_joint_back_when_its_readings_are_late() {
    for (run_us, lost) in [(150_000, 2u32), (350_000, 2), (350_000, 6), (450_000, 0)] {
        let back = turned_back_after(
            Request::JogAngle {
                joint: protocol_core::command::JointId::new(1).unwrap(),
                direction: protocol_core::command::Direction::Positive,
                speed: speed(100),
            },
            run_us,
            lost,
            Request::Stop,
        );
        assert!(
            back <= 0.5,
            "{lost} answers lost at {run_us} us: joint 1 turned back {back:.2} deg after the stop"
        );
    }
}

/// (e) The same for pause during a send_angles that is still speeding up (before: up to
/// 3.9 deg back).
#[test]
fn a_pause_never_turns_a_joint_back_when_its_readings_are_late() {
    for (run_us, lost) in [(300_000, 0u32), (300_000, 3), (400_000, 6)] {
        let back = turned_back_after(
            Request::SendAngles {
                angles: degrees([150.0, 0.0, 0.0, 0.0, 0.0, 0.0]),
                speed: speed(100),
            },
            run_us,
            lost,
            Request::Pause,
        );
        assert!(
            back <= 0.5,
            "{lost} answers lost at {run_us} us: joint 1 turned back {back:.2} deg after pause"
        );
    }
}

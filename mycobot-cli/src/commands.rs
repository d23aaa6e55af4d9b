//! What each subcommand does, and what it prints on stdout.

use std::io::Write;
use std::thread;
use std::time::{Duration, Instant};

use mycobot_api::convert::{angles, pose, pose_to_mm_deg, to_deg};
use protocol_core::command::{
    ErrorCode, GripperSpeed, GripperState, GripperValue, MoveMode, Reply, Request, Rgb,
};
use protocol_core::units::SpeedPercent;

use crate::args::{Command, GripperArg, JogTarget, MotionArgs};
use crate::link::{Failure, Robot, error_reason};
use crate::motion::{Target, error_before, wait_until_arrived};

/// How often a timed jog tells the robot it is still wanted.
const KEEP_JOGGING: Duration = Duration::from_millis(500);

/// Runs `command` on `robot`.
pub fn run(robot: &mut Robot, command: &Command) -> Result<(), Failure> {
    match command {
        Command::Status => status(robot),
        Command::Angles => {
            let now = robot.call(|arm| arm.get_angles())?.map(to_deg);
            say(&angles_line(&now))
        }
        Command::Coords => {
            let now = robot.call(|arm| arm.get_coords())?;
            say(&pose_line(&pose_to_mm_deg(&now)))
        }
        Command::MoveAngles { angles: a, motion } => {
            let target = six(a)?;
            let speed = speed(motion.speed)?;
            let before = (!motion.no_wait).then(|| error_before(robot)).flatten();
            robot.call(|arm| arm.write_angles(angles(target), speed))?;
            finish_move(robot, Target::Angles(target), before, motion)
        }
        Command::MoveCoords {
            pose: p,
            linear,
            motion,
        } => {
            let target = six(p)?;
            let speed = speed(motion.speed)?;
            let mode = if *linear {
                MoveMode::Linear
            } else {
                MoveMode::Joint
            };
            let before = (!motion.no_wait).then(|| error_before(robot)).flatten();
            robot.call(|arm| arm.write_coords(pose(target), speed, mode))?;
            finish_move(robot, Target::Pose(target), before, motion)
        }
        Command::Jog {
            target,
            direction,
            speed: percent,
            duration,
        } => {
            let speed = speed(*percent)?;
            let direction = direction.0;
            robot.call(|arm| match *target {
                JogTarget::Joint(joint) => arm.jog_angle(joint, direction, speed),
                JogTarget::Axis(axis) => arm.jog_coord(axis, direction, speed),
            })?;
            if let Some(seconds) = duration {
                let end =
                    Instant::now() + Duration::try_from_secs_f32(*seconds).unwrap_or_default();
                // Any command is a sign of life to the Atom's jog watchdog, which ends a jog
                // 2 s after the last one.
                while let Some(left) = end.checked_duration_since(Instant::now()) {
                    thread::sleep(left.min(KEEP_JOGGING));
                    if Instant::now() < end {
                        robot.call(|arm| arm.get_angles())?;
                    }
                }
                robot.call(|arm| arm.jog_stop())?;
            }
            Ok(())
        }
        Command::Stop => robot.call(|arm| arm.stop()),
        Command::Gripper {
            action,
            speed: percent,
        } => {
            let speed = GripperSpeed::new(*percent)
                .ok_or_else(|| Failure(format!("gripper speed {percent}: 1..100")))?;
            robot.call(|arm| match *action {
                GripperArg::Open => arm.set_gripper_state(GripperState::Open, speed),
                GripperArg::Close => arm.set_gripper_state(GripperState::Close, speed),
                GripperArg::Release => arm.set_gripper_state(GripperState::Release, speed),
                GripperArg::Value(v) => match GripperValue::new(v) {
                    Some(value) => arm.set_gripper_value(value, speed),
                    None => Ok(()),
                },
            })
        }
        Command::Led { r, g, b } => robot.call(|arm| {
            arm.set_led_rgb(Rgb {
                r: *r,
                g: *g,
                b: *b,
            })
        }),
        Command::Backup { servo } => robot
            .call(|arm| arm.request(&Request::BackupServoParams { servo: servo.0 }))
            .map(drop),
        Command::Restore { servo } => robot
            .call(|arm| arm.request(&Request::RestoreServoParams { servo: servo.0 }))
            .map(drop),
        Command::Watch { interval_ms, count } => {
            watch(robot, Duration::from_millis(*interval_ms), *count)
        }
    }
}

/// Waits for a move unless told not to.
fn finish_move(
    robot: &mut Robot,
    target: Target,
    before: Option<ErrorCode>,
    motion: &MotionArgs,
) -> Result<(), Failure> {
    if motion.no_wait {
        return Ok(());
    }
    let timeout = Duration::try_from_secs_f32(motion.wait_timeout).map_err(|_| {
        Failure(format!(
            "--wait-timeout {}: not a duration",
            motion.wait_timeout
        ))
    })?;
    wait_until_arrived(robot, target, before, timeout)
}

/// The six values clap has counted.
fn six(values: &[f32]) -> Result<[f32; 6], Failure> {
    <[f32; 6]>::try_from(values).map_err(|_| Failure("six values are needed".into()))
}

/// A speed clap has checked to be 1..100.
fn speed(percent: u8) -> Result<SpeedPercent, Failure> {
    SpeedPercent::new(percent).ok_or_else(|| Failure(format!("speed {percent}: 1..100")))
}

/// Prints one line on stdout.
fn say(line: &str) -> Result<(), Failure> {
    let mut out = std::io::stdout().lock();
    writeln!(out, "{line}")
        .and_then(|()| out.flush())
        .map_err(|e| Failure(format!("cannot write the output: {e}")))
}

/// Six angles in degrees, as `angles` prints them.
fn angles_line(a: &[f32; 6]) -> String {
    a.map(|v| format!("{v:.2}")).join(" ")
}

/// A pose, as `coords` prints it: x y z in mm, rx ry rz in degrees.
fn pose_line(p: &[f32; 6]) -> String {
    p.iter()
        .enumerate()
        .map(|(i, v)| {
            if i < 3 {
                format!("{v:.1}")
            } else {
                format!("{v:.2}")
            }
        })
        .collect::<Vec<_>>()
        .join(" ")
}

/// A yes/no answer, or why there is none.
fn yes_no(answer: Result<bool, Failure>) -> String {
    match answer {
        Ok(true) => "yes".into(),
        Ok(false) => "no".into(),
        Err(e) => format!("? ({e})"),
    }
}

/// A version byte (version x 10) asked with `request`.
fn version(robot: &mut Robot, request: Request) -> String {
    match robot.call(|arm| arm.request(&request)) {
        Ok(Some(Reply::Byte(v))) => format!("{:.1}", f32::from(v) / 10.0),
        Ok(_) => "? (no version in the reply)".into(),
        Err(e) => format!("? ({e})"),
    }
}

/// `status`: one "name: value" line each. The robot must answer the first question; a later
/// one it cannot answer says why on its line.
fn status(robot: &mut Robot) -> Result<(), Failure> {
    let powered = robot.call(|arm| arm.is_powered_on())?;
    say(&format!("powered on: {}", yes_no(Ok(powered))))?;
    say(&format!(
        "atom firmware: {}",
        version(robot, Request::GetSystemVersion)
    ))?;
    say(&format!(
        "basic firmware: {}",
        version(robot, Request::GetBasicVersion)
    ))?;
    let angles = match robot.call(|arm| arm.get_angles()) {
        Ok(a) => angles_line(&a.map(to_deg)),
        Err(e) => format!("? ({e})"),
    };
    say(&format!("angles (deg): {angles}"))?;
    let coords = match robot.call(|arm| arm.get_coords()) {
        Ok(p) => pose_line(&pose_to_mm_deg(&p)),
        Err(e) => format!("? ({e})"),
    };
    say(&format!("coords (mm, deg): {coords}"))?;
    say(&format!("error: {}", error_line(robot)))?;
    let moving = robot.call(|arm| arm.check_running());
    say(&format!("moving: {}", yes_no(moving)))
}

/// The last error the robot recorded, in words.
fn error_line(robot: &mut Robot) -> String {
    match robot.call(|arm| arm.get_error_information()) {
        Ok(None) => "none".into(),
        Ok(Some(code)) => error_reason(code),
        Err(e) => format!("? ({e})"),
    }
}

/// `watch`: a header, then a row every `interval` (or as fast as the robot answers), `count`
/// rows or until Ctrl-C. A row the robot does not answer says why in its error column.
fn watch(robot: &mut Robot, interval: Duration, count: Option<u64>) -> Result<(), Failure> {
    say(&format!(
        "{:>7} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7}  error",
        "t_s", "j1", "j2", "j3", "j4", "j5", "j6", "x", "y", "z", "rx", "ry", "rz"
    ))?;
    let start = Instant::now();
    let mut rows = 0u64;
    while count.is_none_or(|n| rows < n) {
        let due = start + interval.saturating_mul(u32::try_from(rows).unwrap_or(u32::MAX));
        thread::sleep(due.saturating_duration_since(Instant::now()));
        let t = start.elapsed().as_secs_f32();
        let mut fields = vec![format!("{t:>7.1}")];
        let mut trouble = None;
        match robot.call(|arm| arm.get_angles()) {
            Ok(a) => fields.extend(a.map(|v| format!("{:>7.2}", to_deg(v)))),
            Err(e) => {
                fields.extend(std::iter::repeat_n(format!("{:>7}", "-"), 6));
                trouble = Some(e);
            }
        }
        match robot.call(|arm| arm.get_coords()) {
            Ok(p) => fields.extend(pose_to_mm_deg(&p).map(|v| format!("{v:>7.1}"))),
            Err(e) => {
                fields.extend(std::iter::repeat_n(format!("{:>7}", "-"), 6));
                trouble.get_or_insert(e);
            }
        }
        let error = match trouble {
            Some(e) => e.to_string(),
            None => error_line(robot),
        };
        say(&format!("{}  {error}", fields.join(" ")))?;
        rows += 1;
    }
    Ok(())
}

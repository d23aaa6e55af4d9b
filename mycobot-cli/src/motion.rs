//! Waiting for a move to arrive: the arm is polled until it is at rest at the target, has
//! stopped short of it (an error, a stop, a limit), or the overall deadline has passed.

use std::io::IsTerminal;
use std::thread;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressStyle};
use mycobot_api::convert::{pose_to_mm_deg, to_deg};
use protocol_core::command::ErrorCode;

use crate::link::{Failure, Robot, error_reason};

/// How often the arm is asked where it is.
const POLL: Duration = Duration::from_millis(50);

/// How long the arm must stand still away from the target to have stopped short of it.
const STILL_FOR: Duration = Duration::from_millis(1000);

/// Closer than this to the previous reading (degrees or millimetres) is standing still.
const STILL_WITHIN: f32 = 0.05;

/// What is being waited for.
#[derive(Debug, Clone, Copy)]
pub enum Target {
    /// Joint angles in degrees; arrived within [`ANGLE_TOLERANCE`].
    Angles([f32; 6]),
    /// A pose, x y z in mm and rx ry rz in degrees; arrived within [`POSE_TOLERANCE`].
    Pose([f32; 6]),
}

/// How close to the target angles is there, in degrees.
pub const ANGLE_TOLERANCE: f32 = 0.5;
/// How close to the target pose is there, in mm (x y z) and degrees (rx ry rz).
pub const POSE_TOLERANCE: f32 = 1.0;

impl Target {
    /// Where the arm is, in the target's terms.
    fn read(&self, robot: &mut Robot) -> Result<[f32; 6], Failure> {
        match self {
            Self::Angles(_) => robot.call(|arm| arm.get_angles()).map(|a| a.map(to_deg)),
            Self::Pose(_) => robot
                .call(|arm| arm.get_coords())
                .map(|p| pose_to_mm_deg(&p)),
        }
    }

    /// The largest difference of any value of `now` from the target.
    fn distance(&self, now: &[f32; 6]) -> f32 {
        match self {
            Self::Angles(target) => largest_difference(target, now, &[false; 6]),
            Self::Pose(target) => {
                largest_difference(target, now, &[false, false, false, true, true, true])
            }
        }
    }

    fn tolerance(&self) -> f32 {
        match self {
            Self::Angles(_) => ANGLE_TOLERANCE,
            Self::Pose(_) => POSE_TOLERANCE,
        }
    }

    fn units(&self) -> &'static str {
        match self {
            Self::Angles(_) => "deg",
            Self::Pose(_) => "mm or deg",
        }
    }
}

/// The largest |a - b|; where `wraps`, as angles (the short way round).
fn largest_difference(a: &[f32; 6], b: &[f32; 6], wraps: &[bool; 6]) -> f32 {
    a.iter()
        .zip(b)
        .zip(wraps)
        .map(|((a, b), wraps)| {
            let d = (a - b).abs();
            if *wraps {
                d.rem_euclid(360.0).min(360.0 - d.rem_euclid(360.0))
            } else {
                d
            }
        })
        .fold(0.0, f32::max)
}

/// Whether the arm says it moves; `None` where the dialect has no such question.
fn moving(robot: &mut Robot) -> Result<Option<bool>, Failure> {
    match robot.call(|arm| arm.check_running()) {
        Ok(m) => Ok(Some(m)),
        Err(_) if robot.dialect() == protocol_core::dialect::Dialect::Seed => Ok(None),
        Err(e) => Err(e),
    }
}

/// The last error the robot recorded, before a move (`None`: none, or no answer).
pub fn error_before(robot: &mut Robot) -> Option<ErrorCode> {
    robot.call(|arm| arm.get_error_information()).ok().flatten()
}

/// Waits until the arm is at rest at `target`, drawing a progress bar on stderr if it is a
/// terminal. Fails if the arm stands still short of it (with the robot's error, if it
/// recorded another than `before`, the one [`error_before`] read before the move) or is not
/// there after `timeout`.
pub fn wait_until_arrived(
    robot: &mut Robot,
    target: Target,
    before: Option<ErrorCode>,
    timeout: Duration,
) -> Result<(), Failure> {
    let start = Instant::now();
    let mut last = target.read(robot)?;
    let first_distance = target.distance(&last).max(f32::EPSILON);
    let bar = progress_bar();
    let mut still_since: Option<Instant> = None;
    let result = loop {
        thread::sleep(POLL);
        let now = target.read(robot)?;
        let distance = target.distance(&now);
        let moving = moving(robot)?;
        if let Some(bar) = &bar {
            let done = (1.0 - distance / first_distance).clamp(0.0, 1.0);
            bar.set_position((done * 100.0) as u64);
        }
        let stepped = largest_difference(&now, &last, &[false; 6]) > STILL_WITHIN;
        last = now;
        let still = moving != Some(true) && !stepped;
        if still && distance <= target.tolerance() {
            break Ok(());
        }
        if !still {
            still_since = None;
        } else if still_since.get_or_insert_with(Instant::now).elapsed() >= STILL_FOR {
            break Err(stopped_short(robot, &target, distance, before));
        }
        if start.elapsed() >= timeout {
            break Err(Failure(format!(
                "not there after {} s: still {distance:.1} {} from the target",
                timeout.as_secs_f32(),
                target.units()
            )));
        }
    };
    if let Some(bar) = bar {
        if result.is_ok() {
            bar.finish();
        } else {
            bar.abandon();
        }
    }
    result
}

/// The line for an arm that stopped `distance` short of `target`, with the error it recorded
/// since the move began (not `before`).
fn stopped_short(
    robot: &mut Robot,
    target: &Target,
    distance: f32,
    before: Option<ErrorCode>,
) -> Failure {
    let short = format!(
        "the arm stopped {distance:.1} {} short of the target",
        target.units()
    );
    match robot.call(|arm| arm.get_error_information()) {
        Ok(Some(code)) if Some(code) != before => {
            Failure(format!("{short}: {}", error_reason(code)))
        }
        _ => Failure(format!(
            "{short} (stopped, or at a limit; the robot recorded no new error)"
        )),
    }
}

/// A bar from 0 to 100 % of the way, on stderr if it is a terminal.
fn progress_bar() -> Option<ProgressBar> {
    if !std::io::stderr().is_terminal() {
        return None;
    }
    let bar = ProgressBar::new(100);
    if let Ok(style) = ProgressStyle::with_template("moving [{bar:40}] {pos:>3} % {elapsed}") {
        bar.set_style(style.progress_chars("=> "));
    }
    Some(bar)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotations_are_compared_the_short_way_round() {
        let a = [0.0, 0.0, 0.0, 179.5, 0.0, -90.0];
        let b = [0.0, 0.0, 0.0, -179.5, 0.0, -90.0];
        assert!(largest_difference(&a, &b, &[false, false, false, true, true, true]) < 1.01);
        assert!(largest_difference(&a, &b, &[false; 6]) > 300.0);
    }
}

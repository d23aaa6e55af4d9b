//! Teach and play, the worked example of a [`Program`] on the Basic (the manual's drag-teaching
//! example, on [`mycobot_api`]):
//!
//! * **A** records: every servo's torque off (release all, 0x13), so the arm can be moved by
//!   hand, and the six angles read [`SAMPLE_PERIOD_US`] apart (get angles, 0x20), up to
//!   [`CAPACITY`] points. **A** again (or **C**, or a full record) ends it and the arm holds
//!   where it was left (power on, 0x10).
//! * **B** plays: power on, a joint move to the first point at [`APPROACH_SPEED_PERCENT`], and once
//!   there (every joint within [`ARRIVED_WITHIN`]) the points sent as a stream of send angles
//!   (0x22) at the period they were recorded at, which the Atom follows as any stream
//!   (docs/motion.md, "Streams"); done once the arm is at the last point.
//! * **C** stops: a record ends, a playback stops at once (stop, 0x29; the seed dialect's 0x28).
//!
//! Every call is started and polled ([`Arm::start`], [`Arm::poll`]), so the loop never waits.
//! A call that fails ends what was under way; the screen shows why ([`TeachStatus::error`]).
//! The record lives in RAM: it is gone at power-off.

use mycobot_api::{Angles, Call, Error};
use protocol_core::command::{Reply, Request};
use protocol_core::units::{Centideg, SpeedPercent};

use crate::io::Buttons;
use crate::program::{Arm, Program};

/// Time between two recorded points: 20 a second, a stream the Atom follows one period behind.
pub const SAMPLE_PERIOD_US: u64 = 50_000;
/// Most points a record holds: 60 s.
pub const CAPACITY: usize = 1_200;
/// Speed of the move to the first point, percent.
pub const APPROACH_SPEED_PERCENT: u8 = 40;
/// Speed cap of the played stream: the Atom's stream follower sets each joint's speed from the
/// points, this only bounds it.
pub const PLAY_SPEED: SpeedPercent = SpeedPercent::MAX;
/// How close every joint must be to a point for the arm to be there: 0.5 deg.
pub const ARRIVED_WITHIN: Centideg = Centideg(50);
/// How often the arm is asked where it is while it moves to the first or rests at the last
/// point.
pub const CHECK_PERIOD_US: u64 = 100_000;
/// Longest wait for the arm to reach the first or the last point.
pub const ARRIVAL_DEADLINE_US: u64 = 30_000_000;

/// What the program is doing, for the screen.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Activity {
    /// Waiting for a button.
    #[default]
    Idle,
    /// Releasing the arm and recording its angles.
    Recording,
    /// Moving to the first point.
    Approaching,
    /// Streaming the points.
    Playing,
    /// Coming to rest at the last point.
    Settling,
    /// Stopping (C).
    Stopping,
}

/// What the screen shows of the program.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TeachStatus {
    /// What it is doing.
    pub activity: Activity,
    /// Points recorded.
    pub points: u16,
    /// Points sent so far in the playback under way (or the last one).
    pub played: u16,
    /// Playbacks finished (the arm at the last point) since power-up.
    pub plays: u16,
    /// Why the last record or playback ended early, if it did.
    pub error: Option<Error>,
}

/// The call under way and what its outcome is for.
#[derive(Debug)]
enum Step {
    /// Release all servos: recording starts.
    Release,
    /// Get angles: one recorded point.
    Sample,
    /// Power on: the record ended, the arm holds.
    Hold,
    /// Power on: playback starts.
    PowerOn,
    /// Send angles to the first point.
    Approach,
    /// Get angles: at the first point yet?
    AtFirst,
    /// Send angles: one point of the stream.
    Point,
    /// Get angles: at the last point yet?
    AtLast,
    /// Stop.
    Stop,
}

/// The teach-and-play program.
#[derive(Debug)]
pub struct Teach {
    status: TeachStatus,
    path: heapless::Vec<Angles, CAPACITY>,
    call: Option<(Call, Step)>,
    /// The buttons on the last pass: a press is a button going down.
    held: Buttons,
    /// When the next point is recorded or sent, or the arm is next asked where it is.
    next_us: u64,
    /// When the arm must have reached the first or the last point.
    deadline_us: u64,
    /// The first button press has been seen released (a button held from power-up does
    /// nothing until it is let go).
    armed: bool,
}

impl Default for Teach {
    fn default() -> Self {
        Self::new()
    }
}

impl Teach {
    /// Waiting for a button, nothing recorded.
    pub const fn new() -> Self {
        Self {
            status: TeachStatus {
                activity: Activity::Idle,
                points: 0,
                played: 0,
                plays: 0,
                error: None,
            },
            path: heapless::Vec::new(),
            call: None,
            held: Buttons {
                a: false,
                b: false,
                c: false,
            },
            next_us: 0,
            deadline_us: 0,
            armed: false,
        }
    }

    /// What the screen shows.
    pub fn status(&self) -> TeachStatus {
        self.status
    }

    /// The recorded points, in order.
    pub fn path(&self) -> &[Angles] {
        &self.path
    }

    fn begin(&mut self, arm: &mut Arm, request: &Request, step: Step) {
        match arm.start(request) {
            Ok(call) => self.call = Some((call, step)),
            Err(error) => self.fail(error),
        }
    }

    fn fail(&mut self, error: Error) {
        self.status.error = Some(error);
        self.status.activity = Activity::Idle;
        self.call = None;
    }

    /// Ends a record: the arm holds where it was left.
    fn end_record(&mut self, arm: &mut Arm) {
        self.begin(arm, &Request::PowerOn, Step::Hold);
    }

    fn on_press(&mut self, pressed: Buttons, arm: &mut Arm) {
        match self.status.activity {
            Activity::Idle if pressed.a => {
                self.path.clear();
                self.status = TeachStatus {
                    activity: Activity::Recording,
                    points: 0,
                    played: 0,
                    error: None,
                    ..self.status
                };
                self.begin(
                    arm,
                    &Request::ReleaseAllServos { undamped: None },
                    Step::Release,
                );
            }
            Activity::Idle if pressed.b && !self.path.is_empty() => {
                self.status.activity = Activity::Approaching;
                self.status.played = 0;
                self.status.error = None;
                self.begin(arm, &Request::PowerOn, Step::PowerOn);
            }
            Activity::Recording if pressed.a || pressed.c => self.end_record(arm),
            Activity::Approaching | Activity::Playing | Activity::Settling if pressed.c => {
                self.status.activity = Activity::Stopping;
                self.begin(arm, &Request::Stop, Step::Stop);
            }
            _ => {}
        }
    }

    /// Acts on the outcome of the call under way.
    fn on_outcome(&mut self, now_us: u64, step: Step, reply: Option<Reply>, arm: &mut Arm) {
        let angles = match reply {
            Some(Reply::Angles(angles)) => Some(angles),
            _ => None,
        };
        match step {
            Step::Release => self.next_us = now_us,
            Step::Sample => {
                if let Some(angles) = angles
                    && self.path.push(angles).is_ok()
                {
                    self.status.points = u16::try_from(self.path.len()).unwrap_or(u16::MAX);
                }
                if self.path.is_full() {
                    self.end_record(arm);
                }
            }
            Step::Hold | Step::Stop => self.status.activity = Activity::Idle,
            Step::PowerOn => match self.path.first() {
                Some(first) => {
                    let request = Request::SendAngles {
                        angles: *first,
                        speed: SpeedPercent::new(APPROACH_SPEED_PERCENT).unwrap_or_default(),
                    };
                    self.begin(arm, &request, Step::Approach);
                }
                None => self.status.activity = Activity::Idle,
            },
            Step::Approach => {
                self.next_us = now_us.saturating_add(CHECK_PERIOD_US);
                self.deadline_us = now_us.saturating_add(ARRIVAL_DEADLINE_US);
            }
            Step::AtFirst | Step::AtLast => {
                let target = match step {
                    Step::AtFirst => self.path.first(),
                    _ => self.path.last(),
                };
                match (angles, target) {
                    (Some(now), Some(target)) if arrived(&now, target) => {
                        if matches!(step, Step::AtFirst) {
                            self.status.activity = Activity::Playing;
                            self.status.played = 1;
                            self.next_us = now_us;
                        } else {
                            self.status.activity = Activity::Idle;
                            self.status.plays = self.status.plays.saturating_add(1);
                        }
                    }
                    _ if now_us >= self.deadline_us => {
                        self.fail(Error::Timeout {
                            cmd: Request::GetAngles.cmd(),
                        });
                    }
                    _ => self.next_us = now_us.saturating_add(CHECK_PERIOD_US),
                }
            }
            Step::Point => self.status.played = self.status.played.saturating_add(1),
        }
    }

    /// Starts the call the activity needs next, if it is due.
    fn next_call(&mut self, now_us: u64, arm: &mut Arm) {
        if now_us < self.next_us {
            return;
        }
        match self.status.activity {
            Activity::Recording => {
                self.next_us = next_tick(self.next_us, now_us);
                self.begin(arm, &Request::GetAngles, Step::Sample);
            }
            Activity::Approaching => self.begin(arm, &Request::GetAngles, Step::AtFirst),
            Activity::Settling => self.begin(arm, &Request::GetAngles, Step::AtLast),
            Activity::Playing => {
                let Some(point) = self.path.get(usize::from(self.status.played)) else {
                    // Every point sent: wait for the arm to rest at the last.
                    self.status.activity = Activity::Settling;
                    self.next_us = now_us.saturating_add(CHECK_PERIOD_US);
                    self.deadline_us = now_us.saturating_add(ARRIVAL_DEADLINE_US);
                    return;
                };
                let request = Request::SendAngles {
                    angles: *point,
                    speed: PLAY_SPEED,
                };
                self.next_us = next_tick(self.next_us, now_us);
                self.begin(arm, &request, Step::Point);
            }
            Activity::Idle | Activity::Stopping => {}
        }
    }
}

impl Program for Teach {
    fn poll(&mut self, now_us: u64, buttons: Buttons, arm: &mut Arm) {
        let pressed = Buttons {
            a: buttons.a && !self.held.a,
            b: buttons.b && !self.held.b,
            c: buttons.c && !self.held.c,
        };
        self.held = buttons;
        if !self.armed {
            // A button read as pressed from power-up (stuck, or an emulator's input that reads
            // 0) counts only once it has been let go.
            self.armed = !(buttons.a || buttons.b || buttons.c);
            return;
        }
        if pressed != Buttons::default() {
            self.on_press(pressed, arm);
        }
        if let Some((mut call, step)) = self.call.take() {
            match arm.poll(&mut call) {
                None => self.call = Some((call, step)),
                Some(Ok(reply)) => self.on_outcome(now_us, step, reply, arm),
                Some(Err(error)) => self.fail(error),
            }
        }
        if self.call.is_none() {
            self.next_call(now_us, arm);
        }
    }
}

/// Every joint of `now` within [`ARRIVED_WITHIN`] of `target`.
fn arrived(now: &Angles, target: &Angles) -> bool {
    now.iter()
        .zip(target)
        .all(|(n, t)| (i32::from(n.0) - i32::from(t.0)).abs() <= i32::from(ARRIVED_WITHIN.0))
}

/// The tick after `tick` on the [`SAMPLE_PERIOD_US`] grid, or a period from `now_us` if the
/// grid fell behind (a slow reply): points stay a period apart, never bunched.
fn next_tick(tick: u64, now_us: u64) -> u64 {
    let next = tick.saturating_add(SAMPLE_PERIOD_US);
    if next <= now_us {
        now_us.saturating_add(SAMPLE_PERIOD_US)
    } else {
        next
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_stay_a_period_apart_even_after_a_slow_reply() {
        assert_eq!(next_tick(1_000, 1_000), 51_000);
        // A reply that took two periods: the next point a period from now, not at once.
        assert_eq!(next_tick(1_000, 120_000), 170_000);
    }

    #[test]
    fn arrived_means_every_joint_within_half_a_degree() {
        let target = [Centideg(1000); 6];
        let mut now = target;
        assert!(arrived(&now, &target));
        now[5] = Centideg(1050);
        assert!(arrived(&now, &target));
        now[5] = Centideg(951 - 2);
        assert!(!arrived(&now, &target));
    }
}

//! Motion stepped in Cartesian space every interpolation period: straight-line moves (send
//! coords mode 1) and Cartesian jogs (0x31, 0x32). Each step solves the inverse kinematics and
//! sends goals that every joint reaches at the same moment.

use kinematics_core::LinearPath;
use protocol_core::command::{MoveMode, Pose};
use protocol_core::units::{Centideg, Steps};

use super::{ActionError, Activity, Atom, Target};
use crate::cartesian;
use crate::config::{JOINTS, SERVOS};
use crate::motion::{self, JogDirection};
use crate::safety::{Goal, GoalSet};

/// Acceleration register of the fastest joint during stepped (linear, jog) motion: 254 x 100
/// steps/s^2, the servo reaches full joint speed in under 70 ms.
const STEP_ACCEL_REGISTER: u8 = 254;

/// A motion stepped in Cartesian space every interpolation period.
// One instance lives inside the Atom (no allocation to box into), so the size of the larger
// variant costs nothing extra.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug)]
pub(super) enum Stepper {
    /// A straight line (send coords mode 1).
    Line {
        path: LinearPath,
        next_us: u64,
        target: Pose,
        speed_percent: u8,
    },
    /// A continuous Cartesian jog: axis 0..2 = x, y, z, 3..5 = rotation about base x, y, z.
    Jog {
        axis: usize,
        direction: JogDirection,
        speed_percent: u8,
        next_us: u64,
        /// The joint angles last commanded (the next step starts from here, not from the
        /// lagging present position).
        angles: [Centideg; JOINTS],
    },
}

impl Atom {
    /// The end pose at the present joint angles.
    pub(crate) fn present_coords(&mut self) -> Pose {
        let angles = self.present_angles();
        self.cart.forward(&angles)
    }

    /// The end pose of the target being executed (present pose when idle).
    pub(crate) fn planned_coords(&mut self) -> Pose {
        if let Some(Stepper::Line { target, .. }) = &self.stepper {
            return *target;
        }
        let angles = self.planned_angles();
        self.cart.forward(&angles)
    }

    /// Moves the end to `pose`: joint-interpolated (mode 0) or along a straight line (mode 1).
    pub(crate) fn move_to_pose(
        &mut self,
        now_us: u64,
        pose: Pose,
        speed_percent: u8,
        mode: MoveMode,
    ) -> Result<(), ActionError> {
        if !self.powered {
            return Err(ActionError::PoweredOff);
        }
        let seed = self.planned_angles();
        let angles = self
            .cart
            .inverse(&pose, &seed)
            .map_err(|_| ActionError::Unreachable)?;
        let target = Target {
            angles: angles.map(Some),
            speed_percent,
            linear: (mode == MoveMode::Linear).then_some(pose),
        };
        // Like any other motion it preempts (fresh mode) or waits its turn (queue mode).
        self.submit_motion(now_us, target)
    }

    /// Starts the straight line from the present position to `pose` (whose joint angles are
    /// `target.angles`).
    pub(super) fn start_line(
        &mut self,
        now_us: u64,
        pose: Pose,
        target: Target,
    ) -> Result<(), ActionError> {
        let present = self.present_angles();
        let start = cartesian::joints(&present);
        let step = self.linear_step_decimm(target.speed_percent);
        let path = LinearPath::new(self.cart.model(), &start, &cartesian::to_kin(&pose), step)
            .map_err(|_| ActionError::Unreachable)?;
        self.stepper = Some(Stepper::Line {
            path,
            next_us: now_us,
            target: pose,
            speed_percent: target.speed_percent,
        });
        self.activity = Activity::Moving {
            target: core::array::from_fn(|j| {
                target
                    .angles
                    .get(j)
                    .copied()
                    .flatten()
                    .unwrap_or(present.get(j).copied().unwrap_or_default())
            }),
            started_us: now_us,
            duration_us: u64::MAX / 4,
            jog: false,
        };
        Ok(())
    }

    /// Distance covered in one interpolation period at `speed_percent`, tenth-millimetres.
    fn linear_step_decimm(&self, speed_percent: u8) -> i32 {
        let v = u64::from(self.config.motion.linear_speed_decimm_per_s)
            * u64::from(speed_percent.clamp(1, 100))
            / 100;
        (v * self.config.timing.interpolation_period_us / 1_000_000).max(1) as i32
    }

    /// Starts a continuous Cartesian jog (0x31, 0x32): `axis` 0..2 along x, y, z, 3..5 about
    /// the base x, y, z axes.
    pub(crate) fn jog_pose(
        &mut self,
        now_us: u64,
        axis: usize,
        direction: JogDirection,
        speed_percent: u8,
    ) -> Result<(), ActionError> {
        if !self.powered {
            return Err(ActionError::PoweredOff);
        }
        self.halt(true);
        self.stepper = Some(Stepper::Jog {
            axis,
            direction,
            speed_percent,
            next_us: now_us,
            angles: self.present_angles(),
        });
        self.activity = Activity::Moving {
            target: self.present_angles(),
            started_us: now_us,
            duration_us: u64::MAX / 4,
            jog: true,
        };
        Ok(())
    }

    /// Takes the next step of a straight line or Cartesian jog when it is due.
    pub(super) fn update_stepper(&mut self, now_us: u64) {
        let period = self.config.timing.interpolation_period_us;
        let Some(stepper) = self.stepper.as_mut() else {
            return;
        };
        let speed_percent = match stepper {
            Stepper::Line { speed_percent, .. } | Stepper::Jog { speed_percent, .. } => {
                *speed_percent
            }
        };
        let next_angles = match stepper {
            Stepper::Line { path, next_us, .. } => {
                if now_us < *next_us {
                    return;
                }
                *next_us = now_us + period;
                match path.next(self.cart.model()) {
                    None => {
                        // Last step sent: the move ends when the joints arrive.
                        self.stepper = None;
                        return;
                    }
                    Some(Err(e)) => Err(if e.protocol_code() == 33 {
                        ActionError::NoLinearSolution
                    } else {
                        ActionError::Unreachable
                    }),
                    Some(Ok(q)) => Ok(cartesian::angles(&q)),
                }
            }
            Stepper::Jog {
                axis,
                direction,
                speed_percent,
                next_us,
                angles,
            } => {
                if now_us < *next_us {
                    return;
                }
                *next_us = now_us + period;
                let (axis, sign, pct, from) = (*axis, direction.sign(), *speed_percent, *angles);
                let pose = self.cart.forward(&from);
                let target = if axis < 3 {
                    let step = self.linear_step_decimm(pct) * sign;
                    let mut a = pose.to_array();
                    if let Some(v) = a.get_mut(axis) {
                        *v = (i32::from(*v) + step).clamp(-32_768, 32_767) as i16;
                    }
                    Pose::from_array(a)
                } else {
                    let v = u64::from(self.config.motion.rotation_speed_centideg_per_s)
                        * u64::from(pct.clamp(1, 100))
                        / 100;
                    let step = (v * period / 1_000_000).max(1) as i32 * sign;
                    self.cart
                        .rotate_about_base(&pose, axis - 3, Centideg(step as i16))
                };
                self.cart
                    .inverse(&target, &from)
                    .map_err(|_| ActionError::Unreachable)
            }
        };
        match next_angles.and_then(|q| self.step_to(&q, period, speed_percent)) {
            Ok(q) => {
                if let Some(Stepper::Jog { angles, .. }) = self.stepper.as_mut() {
                    *angles = q;
                }
            }
            Err(e) => {
                self.record(e);
                self.halt(true);
            }
        }
    }

    /// Sends goals that reach joint angles `q` in one interpolation period, no joint faster
    /// than the joint speed at `speed_percent` (a long step then takes longer than a period).
    fn step_to(
        &mut self,
        q: &[Centideg; JOINTS],
        period_us: u64,
        speed_percent: u8,
    ) -> Result<[Centideg; JOINTS], ActionError> {
        self.check_target(&Target {
            angles: q.map(Some),
            speed_percent: 100,
            linear: None,
        })?;
        let present = self.present_steps();
        let max_speed = u64::from(motion::joint_speed_steps(&self.config, speed_percent));
        let goal_steps: [Steps; JOINTS] =
            core::array::from_fn(|j| self.goal_steps(j, q.get(j).copied().unwrap_or_default()));
        let travel = |j: usize| -> u64 {
            match (goal_steps.get(j), present.get(j)) {
                (Some(g), Some(p)) => u64::from((i32::from(g.0) - i32::from(p.0)).unsigned_abs()),
                _ => 0,
            }
        };
        // The step takes one period, or longer if the farthest joint cannot make it in time;
        // every joint's speed is scaled to that time so all arrive together.
        let longest = (0..JOINTS).map(travel).max().unwrap_or(0);
        let step_us = (longest * 1_000_000 / max_speed.max(1)).max(period_us.max(1));
        let mut goals: GoalSet = [None; SERVOS];
        for (j, slot) in goals.iter_mut().take(JOINTS).enumerate() {
            let speed = (travel(j) * 1_000_000 / step_us).clamp(1, max_speed.max(1));
            // Steps need a brisk ramp (the servo must reach the step speed within a fraction
            // of a period), scaled by the joint's share like the speed, so every joint follows
            // the same time-scaled profile and the end stays on the line.
            let accel = (u64::from(STEP_ACCEL_REGISTER) * travel(j) / longest.max(1)).max(1);
            *slot = goal_steps.get(j).map(|&position| Goal {
                position,
                speed_steps_per_s: speed.min(u64::from(u16::MAX)) as u16,
                accel: accel.min(254) as u8,
            });
        }
        self.send_goals(goals)?;
        if let Activity::Moving {
            target, jog: true, ..
        } = &mut self.activity
        {
            *target = *q;
        }
        Ok(*q)
    }
}

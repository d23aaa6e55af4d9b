//! The Atom's parts side by side, each owning its state; [`crate::commands`] acts on them and
//! [`crate::Atom`] runs them. Nothing here knows the host protocol.

use crate::bank::ServoBank;
use crate::collision::CollisionDetector;
use crate::config::JOINTS;
use crate::context::Context;
use crate::dispenser::Dispenser;
use crate::drag::DragRecorder;
use crate::error::{AtomError, ErrorLog};
use crate::flash_writes::FlashWrites;
use crate::gripper::Gripper;
use crate::motion::MotionController;
use crate::settings::Settings;
use crate::waiting::WaitingReads;

/// The parts a command acts on.
#[derive(Clone, Debug)]
pub struct Parts {
    /// What the host set.
    pub settings: Settings,
    /// The servos.
    pub bank: ServoBank,
    /// The motion.
    pub motion: MotionController,
    /// The gripper.
    pub gripper: Gripper,
    /// Drag teaching.
    pub drag: DragRecorder,
    /// The accessory servo.
    pub dispenser: Dispenser,
    /// The error state (0x07).
    pub errors: ErrorLog,
    /// Requests whose replies wait for servo reads (0x53, 0x2D, 0xEA/0xEB).
    pub waiting: WaitingReads,
    /// Collision detection.
    pub collision: CollisionDetector,
    /// Records waiting to be written to flash until the arm is quiet.
    pub flash_writes: FlashWrites,
}

impl Parts {
    /// The parts at boot, with `settings`.
    pub fn new(settings: Settings) -> Self {
        Self {
            bank: ServoBank::new(&settings),
            motion: MotionController::new(),
            gripper: Gripper::new(&settings),
            drag: DragRecorder::new(),
            dispenser: Dispenser::default(),
            errors: ErrorLog::default(),
            waiting: WaitingReads::default(),
            collision: CollisionDetector::default(),
            flash_writes: FlashWrites::default(),
            settings,
        }
    }

    /// Looks at the joints' fresh state reads for a collision; on one, the arm stops
    /// ([`MotionController::collided`]) and the error is recorded for 0x07.
    pub fn watch_collisions(&mut self, now_us: u64) {
        let kind = self.motion.collision_kind();
        let mut found = None;
        for joint in 0..JOINTS {
            let (Some(state), Some(read_us)) =
                (self.bank.health(joint), self.bank.read_at_us(joint))
            else {
                continue;
            };
            let settings = self.settings.collision();
            found = found.or(self
                .collision
                .on_state(now_us, joint, read_us, state, settings, kind));
        }
        if let Some(collision) = found {
            let cx = &mut Context::new(now_us, &mut self.bank, &self.settings);
            self.motion.collided(cx, &collision);
            self.errors.record(AtomError::Collision(collision.kind));
        }
    }

    /// Forgets a collision (0x08 clear error information, 0x10 power on): motion is allowed
    /// again, and 0x07 no longer reports it.
    pub fn clear_collision(&mut self) {
        if self.collision.collision().is_some() {
            self.errors.clear();
        }
        self.collision.clear();
        self.motion.unlock();
    }

    /// True at `now_us` while the arm moves ([`MotionController::is_moving`]).
    pub fn is_moving(&self, now_us: u64) -> bool {
        self.motion.is_moving(&self.bank, now_us)
    }
}

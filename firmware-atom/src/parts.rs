//! The Atom's parts side by side, each owning its state; [`crate::commands`] acts on them and
//! [`crate::Atom`] runs them. Nothing here knows the host protocol.

use crate::bank::ServoBank;
use crate::dispenser::Dispenser;
use crate::drag::DragRecorder;
use crate::error::ErrorLog;
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
            settings,
        }
    }

    /// True at `now_us` while the arm moves ([`MotionController::is_moving`]).
    pub fn is_moving(&self, now_us: u64) -> bool {
        self.motion.is_moving(&self.bank, now_us)
    }
}

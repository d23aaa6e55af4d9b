//! The Atom: its parts ([`Parts`]) side by side, run in [`Atom::poll`]; each step lends the
//! servo bank and the settings to the part that acts through one [`Context`].
//!
//! * [`crate::settings::Settings`]: what the host set (limits, modes, frames).
//! * [`crate::bank::ServoBank`]: the servos' state and the goals sent to them (the only maker
//!   of goals, through the safety check).
//! * [`crate::motion::MotionController`]: moves, paths, streams, jogs, braking, the queue.
//! * [`crate::gripper::Gripper`]: the gripper's range and settings.
//! * [`crate::drag::DragRecorder`]: drag teaching, fed from the bank's state reads.
//! * [`crate::dispenser::Dispenser`]: the accessory hobby servo (0xD4 / 0xD7).
//! * [`crate::error::ErrorLog`]: the error state 0x07 reports.
//! * [`crate::waiting::WaitingReads`]: requests whose replies wait for servo reads.
//! * [`crate::collision::CollisionDetector`]: collision protection, fed from the state reads.
//! * [`BusSchedule`]: who talks on the shared wire when; [`UsbLink`]: the Atom's own USB.
//!
//! [`crate::commands`] translates each request into calls on these parts.

use protocol_core::units::{Centideg, Steps};
use protocol_core::{BytePort, Frame};

use crate::collision::{Collision, CollisionSettings};
use crate::config::{AtomConfig, ConfigError, JOINTS, JointLimit, SERVOS};
use crate::context::Context;
use crate::driver::{Op, Outcome, Taken};
use crate::flash_writes::QUIET_US;
use crate::io::AtomIo;
use crate::link::{Link, READ_BUDGET, UsbLink};
use crate::parts::Parts;
use crate::schedule::{BusEvent, BusEvents, BusSchedule};
use crate::settings::Settings;
use crate::store::ParamStore;

/// The Atom firmware. Create it once with [`Atom::new`] and call [`Atom::poll`] in a loop.
pub struct Atom {
    parts: Parts,
    /// The time of the last poll: what the accessors below answer as of.
    polled_us: u64,
    schedule: BusSchedule,
    usb: UsbLink,
    button_was_pressed: bool,
    config_error: Option<ConfigError>,
    /// The settings kept in flash were loaded (at the first poll, where the store is lent).
    stored_settings_loaded: bool,
    /// When the last request (bus or USB) was heard: records wait for flash until the arm has
    /// been quiet for [`QUIET_US`].
    last_request_us: u64,
}

impl Atom {
    /// An Atom with `config`. An invalid configuration is replaced by the default one and the
    /// reason kept in [`Atom::config_error`], so a board always boots into something safe.
    pub fn new(config: AtomConfig) -> Self {
        let (config, config_error) = match config.validate() {
            Ok(()) => (config, None),
            Err(e) => (AtomConfig::default(), Some(e)),
        };
        Self {
            parts: Parts::new(Settings::new(config)),
            polled_us: 0,
            schedule: BusSchedule::new(config.timing.reply_margin_us),
            usb: UsbLink::new(),
            button_was_pressed: false,
            config_error,
            stored_settings_loaded: false,
            last_request_us: 0,
        }
    }

    /// Runs everything that is due at `now_us` (monotonic microseconds): reads the bytes that
    /// arrived on `bus` (the shared 1 Mbaud wire) and `usb` (the Atom's own host link,
    /// [`protocol_core::NullPort`] if unused), answers host commands, drives the servo
    /// transactions and the motion. Never blocks; call it as often as possible.
    pub fn poll<B: BytePort, U: BytePort, I: AtomIo>(
        &mut self,
        now_us: u64,
        bus: &mut B,
        usb: &mut U,
        io: &mut I,
    ) {
        self.polled_us = now_us;
        if !self.stored_settings_loaded {
            self.stored_settings_loaded = true;
            self.load_stored_settings(io);
        }
        // One buffer for the whole pass, filled and emptied in place (`BusSchedule::hear`).
        let mut events = BusEvents::new();
        for _ in 0..READ_BUDGET {
            let Some(byte) = bus.read_byte() else { break };
            self.schedule.hear(now_us, byte, &mut events);
            for event in events.drain(..) {
                self.on_bus_event(now_us, event, usb, io);
            }
        }
        self.schedule.on_time(now_us, &mut events);
        for event in events.drain(..) {
            self.on_bus_event(now_us, event, usb, io);
        }
        self.receive_usb(now_us, usb, io);
        if let Some((op, outcome)) = self.schedule.poll_driver(now_us, bus) {
            self.finish(now_us, op, outcome, usb, io);
        }
        self.parts.watch_collisions(now_us);
        let p = &mut self.parts;
        let moved = p
            .motion
            .update(&mut Context::new(now_us, &mut p.bank, &p.settings));
        p.errors.note(moved).ok();
        self.parts.drag.poll(now_us, &self.parts.bank);
        self.parts.dispenser.poll(now_us, io);
        self.update_button(io);
        self.schedule
            .start_next(now_us, bus, &mut self.parts.bank, &self.parts.settings);
        self.write_flash_when_quiet(now_us, io);
    }

    /// Writes one record waiting for the flash ([`crate::flash_writes`]) if the arm is quiet:
    /// no request heard for [`QUIET_US`], no motion under way, no servo known to move, no
    /// drag teaching being recorded, no servo transaction, reply or read under way. The flash
    /// stops the chip meanwhile. A servo that does not answer, or an arm released and off its
    /// goals, does not keep the records from the flash.
    fn write_flash_when_quiet<I: AtomIo>(&mut self, now_us: u64, io: &mut I) {
        let p = &self.parts;
        let quiet = !p.flash_writes.is_empty()
            && now_us.saturating_sub(self.last_request_us) >= QUIET_US
            && !p.motion.is_active()
            && (0..SERVOS).all(|i| !p.bank.servo_moving(now_us, i))
            && !p.drag.is_recording()
            && p.waiting.is_empty()
            && self.schedule.is_idle();
        if let (true, Some(flash)) = (quiet, io.param_store()) {
            // A failure leaves the change in force until a restart (flash_writes).
            let _ = self.parts.flash_writes.write_one(flash);
        }
    }

    fn on_bus_event<U: BytePort, I: AtomIo>(
        &mut self,
        now_us: u64,
        event: BusEvent,
        usb: &mut U,
        io: &mut I,
    ) {
        match event {
            BusEvent::Frame(frame) => {
                self.last_request_us = now_us;
                if let Some(reply) =
                    crate::commands::handle(&mut self.parts, now_us, &frame, Link::Bus, io)
                {
                    self.schedule.send_reply(reply);
                }
            }
            BusEvent::Packet(packet) => match self.schedule.on_packet(packet) {
                Some(Taken::Finished(op, outcome)) => self.finish(now_us, op, outcome, usb, io),
                Some(Taken::Late {
                    op,
                    answer,
                    sent_us,
                }) => {
                    // A state read of the refresh is dated when it was asked (the state is
                    // at least that old); anything else, a read a job waits for, is done now.
                    let at = if self.parts.bank.is_refresh_read(&op) {
                        sent_us
                    } else {
                        now_us
                    };
                    self.finish(at, op, Outcome::Answered(answer), usb, io);
                }
                None => {}
            },
        }
    }

    fn receive_usb<U: BytePort, I: AtomIo>(&mut self, now_us: u64, usb: &mut U, io: &mut I) {
        let parts = &mut self.parts;
        let last_request_us = &mut self.last_request_us;
        let mut answer = |frame: Frame, usb: &mut U| {
            *last_request_us = now_us;
            if let Some(reply) = crate::commands::handle(parts, now_us, &frame, Link::Usb, io) {
                usb.write(&reply.to_bytes());
            }
        };
        let mut frames: heapless::Vec<Frame, { crate::schedule::MAX_FRAMES_AT_ONCE }> =
            heapless::Vec::new();
        for _ in 0..READ_BUDGET {
            let Some(byte) = usb.read_byte() else { break };
            self.usb.push(now_us, byte, &mut |f| {
                let _ = frames.push(f);
            });
            for frame in frames.drain(..) {
                answer(frame, usb);
            }
        }
        self.usb.on_time(now_us, &mut |f| {
            let _ = frames.push(f);
        });
        for frame in frames.drain(..) {
            answer(frame, usb);
        }
    }

    /// Applies the result of a finished servo transaction; sends a reply that waited for it
    /// (the one completion path, [`crate::waiting`]).
    fn finish<U: BytePort, I: AtomIo>(
        &mut self,
        now_us: u64,
        op: Op,
        outcome: Outcome,
        usb: &mut U,
        io: &mut I,
    ) {
        let corrupt = self.schedule.saw_corruption();
        let p = &mut self.parts;
        let Some(done) = p.bank.finish(now_us, &p.settings, op, outcome, corrupt) else {
            return;
        };
        let cx = &mut Context::new(now_us, &mut p.bank, &p.settings);
        let mut flash = p.flash_writes.over(io.param_store());
        let store = flash.as_mut().map(|f| f as &mut dyn ParamStore);
        let reply = p.waiting.complete(cx, &mut p.motion, store, done);
        match reply {
            Some((Link::Bus, reply)) => self.schedule.send_reply(reply),
            Some((Link::Usb, reply)) => usb.write(&reply.to_bytes()),
            None => {}
        }
    }

    /// Takes over the settings kept in the flash the board lends (collision protection); without
    /// a store or a valid record the defaults stay.
    fn load_stored_settings<I: AtomIo>(&mut self, io: &mut I) {
        if let Some(stored) = io.param_store().and_then(CollisionSettings::load) {
            *self.parts.settings.collision_mut() = stored;
        }
    }

    /// Free mode: the button releases the joints while held (to move the arm by hand).
    fn update_button<I: AtomIo>(&mut self, io: &mut I) {
        let pressed = io.button_pressed();
        let p = &mut self.parts;
        if pressed != self.button_was_pressed && p.settings.free_mode() && p.bank.powered() {
            if pressed {
                p.motion.abandon();
            }
            for j in 0..JOINTS {
                p.bank.set_torque(&p.settings, j, !pressed);
            }
        }
        self.button_was_pressed = pressed;
    }

    // ----- accessors ----------------------------------------------------------------------

    /// The configuration in use.
    pub fn config(&self) -> &AtomConfig {
        self.parts.settings.config()
    }

    /// Why the configuration passed to [`Atom::new`] was refused, if it was.
    pub fn config_error(&self) -> Option<ConfigError> {
        self.config_error
    }

    /// True while the arm is powered on (torque enabled by 0x10, until 0x11).
    pub fn is_powered(&self) -> bool {
        self.parts.bank.powered()
    }

    /// True while the arm moves (a motion runs or a joint reports moving).
    pub fn is_moving(&self) -> bool {
        self.parts.is_moving(self.polled_us)
    }

    /// The collision detected and not cleared yet (0x08, 0x10 clear it).
    pub fn collision(&self) -> Option<Collision> {
        self.parts.collision.collision()
    }

    /// The error code 0x07 reports (0 = none).
    pub fn error_code(&self) -> u8 {
        self.parts.errors.code()
    }

    /// Present joint angles, from the servos' last reported positions.
    pub fn present_angles(&self) -> [Centideg; JOINTS] {
        self.parts
            .bank
            .present_angles(self.polled_us, &self.parts.settings)
    }

    /// Present encoder positions of the joints.
    pub fn present_steps(&self) -> [Steps; JOINTS] {
        self.parts.bank.present_steps()
    }

    /// Current joint limits (settable at run time with 0x4C/0x4D).
    pub fn joint_limits(&self) -> &[JointLimit; JOINTS] {
        self.parts.settings.limits()
    }

    /// Completed state-refresh rounds (every servo read once per round). Wraps.
    pub fn refresh_rounds(&self) -> u32 {
        self.parts.bank.refresh_rounds()
    }

    /// Gripper opening 0 (closed) ..= 100 (open) from its present position.
    pub fn gripper_value(&self) -> u8 {
        self.parts.gripper.value(&self.parts.bank)
    }

    /// The coordinate frames the host selected (tool pose, world pose, reference frame, end
    /// type) and the kinematics model they configure, as coordinates are reported with.
    pub fn cartesian(&self) -> &crate::cartesian::Cartesian {
        self.parts.settings.cart()
    }

    /// Drag-teaching points recorded (0xF4), and whether it is still recording (a full buffer
    /// stops it).
    pub fn drag_record(&self) -> (u16, bool) {
        (self.parts.drag.recorded(), self.parts.drag.is_recording())
    }
}

#[cfg(test)]
mod tests {
    use std::vec::Vec;

    use protocol_core::FrameDecoder;
    use protocol_core::command::cmd;
    use protocol_core::servo::{Instruction, reg};
    use protocol_core::timing::HOST_BAUD;
    use sim_hw::wire::SerialPort;
    use sim_hw::{Bus, HeardByte, SerialLine, ServoChain, SimServo, StationId};

    use super::*;
    use crate::io::RecordingIo;
    use crate::store::{COLLISION_SETTINGS_KEY, ParamStore};

    /// How often the Atom is polled, microseconds (it must be at least every 10 us).
    const TICK_US: u64 = 5;
    /// The bus ids of the arm's servos: joints 1..=6, then the gripper.
    const IDS: core::ops::RangeInclusive<u8> = 1..=7;
    /// `is_power_on` (0x12) as a host sends it.
    const IS_POWER_ON: [u8; 5] = [0xFE, 0xFE, 0x02, cmd::IS_POWER_ON, 0xFA];

    /// The Atom on the simulated 1 Mbaud wire with the arm's seven servos (torque on, as in an
    /// arm powered before the Atom booted), its USB serial (115200 both ways) and its IO, in
    /// virtual time.
    struct Arm {
        atom: Atom,
        wire: Bus,
        station: StationId,
        servos: ServoChain,
        usb_to_atom: SerialLine,
        usb_from_atom: SerialLine,
        io: RecordingIo,
        now_us: u64,
        /// Host frames the Atom sent on the wire.
        frames_on_bus: Vec<Frame>,
        bus_frames: FrameDecoder,
    }

    impl Arm {
        fn new(config: AtomConfig, io: RecordingIo) -> Self {
            let mut wire = Bus::mycobot(7);
            wire.set_tap(true); // the servos hear the wire through the tap
            let station = wire.attach(true);
            let mut servos = ServoChain::new();
            for id in IDS {
                let mut servo = SimServo::new(id, 2048);
                let torque_on = Instruction::Write {
                    addr: reg::TORQUE_ENABLE,
                    data: &[1],
                };
                servo.receive(&torque_on.to_packet(id).unwrap(), 0);
                servos.attach(&mut wire, servo);
            }
            Self {
                atom: Atom::new(config),
                wire,
                station,
                servos,
                usb_to_atom: SerialLine::new(HOST_BAUD),
                usb_from_atom: SerialLine::new(HOST_BAUD),
                io,
                now_us: 0,
                frames_on_bus: Vec::new(),
                bus_frames: FrameDecoder::new(),
            }
        }

        /// Runs the wire, the servos and the Atom for `us` microseconds.
        fn run_us(&mut self, us: u64) {
            let end = self.now_us + us;
            while self.now_us < end {
                self.now_us += TICK_US;
                let now_ns = self.now_us * 1_000;
                let mut heard: Vec<HeardByte> = Vec::new();
                self.wire.deliver(now_ns);
                self.wire.take_heard(&mut heard);
                for byte in &heard {
                    self.servos.hear(byte);
                    if byte.from == self.station {
                        let frames = &mut self.frames_on_bus;
                        self.bus_frames.feed(&[byte.byte], |f| frames.push(f));
                    }
                }
                self.servos.transmit_due(now_ns, &mut self.wire);
                self.usb_to_atom.deliver(now_ns);
                self.usb_from_atom.deliver(now_ns);
                let mut bus = self.wire.port(self.station).unwrap();
                let mut usb = SerialPort {
                    rx: &mut self.usb_to_atom,
                    tx: &mut self.usb_from_atom,
                    now_ns,
                };
                self.atom
                    .poll(self.now_us, &mut bus, &mut usb, &mut self.io);
                self.wire.start_transmissions(now_ns);
            }
        }

        fn run_ms(&mut self, ms: u64) {
            self.run_us(ms * 1_000);
        }

        /// Sends `bytes` on the Atom's USB and returns the data of the frames it answered there
        /// within 100 ms.
        fn usb_exchange(&mut self, bytes: &[u8]) -> Vec<Vec<u8>> {
            self.usb_to_atom.send(self.now_us * 1_000, bytes);
            self.run_ms(100);
            let mut received = Vec::new();
            self.usb_from_atom.receive_all(&mut received);
            let mut replies = Vec::new();
            FrameDecoder::new().feed(&received, |f| replies.push(f.data().to_vec()));
            replies
        }

        /// Asks `code` with `data` on the Atom's USB; the data of its one reply.
        fn ask(&mut self, code: u8, data: &[u8]) -> Vec<u8> {
            let replies = self.usb_exchange(&Frame::new(code, data).unwrap().to_bytes());
            assert_eq!(replies.len(), 1, "replies to {code:#04x}: {replies:?}");
            replies.into_iter().next().unwrap_or_default()
        }

        /// Presses (`true`) or lets go of the Atom's button, and runs 20 ms.
        fn hold_button(&mut self, pressed: bool) {
            self.io.button = pressed;
            self.run_ms(20);
        }

        /// Whether each servo (joints 1..=6, gripper) holds torque.
        fn torque(&self) -> Vec<bool> {
            IDS.map(|id| self.servos.get(id).unwrap().torque_enabled())
                .collect()
        }
    }

    fn powered() -> AtomConfig {
        AtomConfig {
            powered_at_boot: true,
            ..AtomConfig::default()
        }
    }

    /// The real arm, powered, with nothing in flash, after its first 50 ms.
    fn powered_arm() -> Arm {
        let mut arm = Arm::new(powered(), RecordingIo::default());
        arm.run_ms(50);
        arm
    }

    #[test]
    fn a_refused_configuration_boots_the_default_one_and_says_why() {
        // The gripper on the broadcast id: refused, so the arm runs with the real ids.
        let bad = AtomConfig {
            servo_ids: [1, 2, 3, 4, 5, 6, 0xFE],
            ..powered()
        };
        let mut arm = Arm::new(bad, RecordingIo::default());
        assert_eq!(arm.atom.config_error(), Some(ConfigError::BadServoId));
        assert_eq!(arm.atom.config(), &AtomConfig::default());
        arm.run_ms(50);
        assert_eq!(
            arm.ask(cmd::IS_SERVO_ENABLED, &[7]),
            [7, 1],
            "the gripper, servo 7, is read and holds"
        );

        let good = Atom::new(powered());
        assert_eq!(good.config_error(), None);
        assert!(
            good.config().powered_at_boot,
            "a valid configuration is kept"
        );
    }

    /// Flash holding collision protection off and joint 2's threshold at 180.
    fn flash_with_collision_settings() -> RecordingIo {
        let mut io = RecordingIo::default();
        let mut stored = CollisionSettings::new(false);
        stored.set_threshold(2, 180).unwrap();
        stored.save(&mut io.params).unwrap();
        io
    }

    #[test]
    fn collision_settings_kept_in_flash_are_in_force_from_the_first_poll() {
        let mut arm = Arm::new(powered(), flash_with_collision_settings());
        arm.run_us(TICK_US);
        assert_eq!(arm.ask(cmd::GET_COLLISION_MODE, &[]), [0]);
        assert_eq!(
            arm.ask(cmd::GET_COLLISION_THRESHOLDS, &[]),
            [100, 180, 100, 100, 100, 100]
        );
        // Read once, at boot: the flash is not read again on every poll.
        CollisionSettings::new(true)
            .save(&mut arm.io.params)
            .unwrap();
        assert_eq!(arm.ask(cmd::GET_COLLISION_MODE, &[]), [0]);
    }

    #[test]
    fn a_record_that_is_not_valid_settings_leaves_the_defaults() {
        let mut io = RecordingIo::default();
        io.params.store(COLLISION_SETTINGS_KEY, &[1, 7, 7]).unwrap();
        let mut arm = Arm::new(powered(), io);
        assert_eq!(arm.ask(cmd::GET_COLLISION_MODE, &[]), [1]);
        assert_eq!(arm.ask(cmd::GET_COLLISION_THRESHOLDS, &[]), [100; 6]);
    }

    #[test]
    fn the_button_releases_the_joints_while_held_in_free_mode_only() {
        let mut arm = powered_arm();
        assert_eq!(arm.torque(), [true; 7]);
        arm.hold_button(true);
        assert_eq!(
            arm.torque(),
            [true; 7],
            "free mode off: the button does nothing"
        );
        arm.hold_button(false);

        assert_eq!(arm.ask(cmd::SET_FREE_MODE, &[1]), [1]);
        arm.hold_button(true);
        let mut joints_limp = [false; 7];
        joints_limp[6] = true;
        assert_eq!(
            arm.torque(),
            joints_limp,
            "the joints limp, the gripper holds"
        );
        arm.hold_button(false);
        assert_eq!(arm.torque(), [true; 7], "released: every joint holds again");
    }

    #[test]
    fn the_button_does_not_power_an_arm_that_was_switched_off() {
        let mut arm = powered_arm();
        assert_eq!(arm.ask(cmd::SET_FREE_MODE, &[1]), [1]);
        assert_eq!(arm.ask(cmd::POWER_OFF, &[]), [1]);
        assert_eq!(arm.torque(), [false; 7]);
        arm.hold_button(true);
        arm.hold_button(false);
        assert_eq!(arm.torque(), [false; 7], "pressing and releasing it");
    }

    #[test]
    fn a_request_on_the_atoms_usb_is_answered_there_and_never_on_the_bus() {
        let mut arm = powered_arm();
        assert_eq!(arm.usb_exchange(&IS_POWER_ON), [[1]]);
        assert!(arm.frames_on_bus.is_empty(), "{:?}", arm.frames_on_bus);
        // A client killed in the middle of a frame (a header announcing 16 bytes), then the
        // next one, after a pause: its request is answered, once.
        assert!(arm.usb_exchange(&[0xFE, 0xFE, 0x10, 0x20]).is_empty());
        assert_eq!(arm.usb_exchange(&IS_POWER_ON), [[1]]);
    }
}

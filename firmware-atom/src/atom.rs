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
use crate::config::{AtomConfig, ConfigError, JOINTS, JointLimit};
use crate::context::Context;
use crate::driver::{Op, Outcome};
use crate::io::AtomIo;
use crate::link::{Link, READ_BUDGET, UsbLink};
use crate::parts::Parts;
use crate::schedule::{BusEvent, BusSchedule};
use crate::settings::Settings;

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
        for _ in 0..READ_BUDGET {
            let Some(byte) = bus.read_byte() else { break };
            for event in self.schedule.hear(now_us, byte) {
                self.on_bus_event(now_us, event, usb, io);
            }
        }
        for event in self.schedule.on_time(now_us) {
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
                if let Some(reply) =
                    crate::commands::handle(&mut self.parts, now_us, &frame, Link::Bus, io)
                {
                    self.schedule.send_reply(reply);
                }
            }
            BusEvent::Packet(packet) => {
                if let Some((op, outcome)) = self.schedule.on_packet(packet) {
                    self.finish(now_us, op, outcome, usb, io);
                }
            }
        }
    }

    fn receive_usb<U: BytePort, I: AtomIo>(&mut self, now_us: u64, usb: &mut U, io: &mut I) {
        let parts = &mut self.parts;
        let mut answer = |frame: Frame, usb: &mut U| {
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
        let reply = p
            .waiting
            .complete(cx, &mut p.motion, io.param_store(), done);
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

//! Looks after the Atom and keeps the status the LCD shows: makes sure the Atom is powered after
//! boot, probes it (0x12) when it has been silent for a while, and watches the forwarder's
//! events and the replies' deliveries for the status. It decides nothing about the clients'
//! traffic (where a reply goes is the router's decision, [`crate::router`]); it only asks the
//! Atom its own questions (the probe, the boot power-on), which go out only when the bus has
//! nothing else to do.
//!
//! The boot power-on never cuts a move short. The vendor transponder sends power on (0x10) at
//! boot, and the Atom answers 0x10 by holding the arm where it is: a move the host started in
//! the Basic's first second (or before the Basic restarted) would stop halfway. So the Basic
//! first asks (0x12) and sends 0x10 only if the Atom says it is off, with no host request
//! having reached the Atom between that answer and the 0x10 (else it asks again). An Atom that
//! is off runs no motion (it refuses moves while off), so this 0x10 stops nothing. A host power
//! on, power off or release (0x10, 0x11, 0x13) decides the power itself, and the Basic no
//! longer does.
//! Button A is the user asking in person: a press (the button going from released to pressed)
//! sends 0x10 at once, once; a button held, or read as pressed from boot (a stuck button, an
//! emulator that reads every input as 0), does nothing until it has been released.

use protocol_core::Frame;
use protocol_core::command::cmd;

use crate::config::BasicConfig;
use crate::forwarder::Event;
use crate::io::Buttons;
use crate::request::{Delivery, Origin, Request};
use crate::status::{AtomLink, BasicError, BasicStatus};

/// What the Basic still has to do about the Atom's power.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum PowerTask {
    /// Nothing: the Atom is on, or the host decides.
    Done,
    /// Make sure the Atom is on (boot): ask, and power on only if it is off. `off_seen`: it
    /// answered off, and no host request has been forwarded since.
    Ensure { off_seen: bool },
    /// Power on now, once (button A).
    Now,
}

/// The supervisor's state.
#[derive(Debug)]
pub(crate) struct Supervisor {
    pub(crate) status: BasicStatus,
    /// What the Basic still has to do about the Atom's power.
    power: PowerTask,
    /// Earliest time of the next internal request.
    next_internal_us: u64,
    /// When the Atom last answered anything.
    last_answer_us: u64,
    /// The buttons as last read. A press is a button going from released to pressed, so at
    /// boot every button counts as held: one that reads pressed from the start must be
    /// released before it counts.
    buttons: Buttons,
    /// Internal requests are tried again (probing is on).
    retries: bool,
}

impl Supervisor {
    pub(crate) fn new(config: &BasicConfig) -> Self {
        Self {
            status: BasicStatus {
                version_x10: config.version_x10,
                ..BasicStatus::default()
            },
            power: if config.power_on_at_boot {
                PowerTask::Ensure { off_seen: false }
            } else {
                PowerTask::Done
            },
            next_internal_us: 0,
            last_answer_us: 0,
            buttons: Buttons {
                a: true,
                b: true,
                c: true,
            },
            retries: config.probe_interval_us > 0,
        }
    }

    /// The Basic booted at `now_us`.
    pub(crate) fn boot(&mut self, now_us: u64, config: &BasicConfig) {
        self.last_answer_us = now_us;
        self.next_internal_us = now_us.saturating_add(config.boot_power_on_delay_us);
    }

    /// Records a problem for the display.
    pub(crate) fn error(&mut self, error: BasicError) {
        self.status.last_error = Some(error);
    }

    /// A host frame with command `code` arrived (framed mode).
    pub(crate) fn on_host_request(&mut self, code: u8) {
        self.status.host_frames = self.status.host_frames.wrapping_add(1);
        if matches!(
            code,
            cmd::POWER_ON | cmd::POWER_OFF | cmd::RELEASE_ALL_SERVOS
        ) {
            // The host has taken charge of the arm's power: do not power it on behind its back.
            self.power = PowerTask::Done;
        }
    }

    /// The internal request to send now, if any. `idle` is true when nothing else is queued
    /// or in flight: internal requests never delay the host's.
    pub(crate) fn next_internal(
        &mut self,
        now_us: u64,
        config: &BasicConfig,
        buttons: Buttons,
        idle: bool,
    ) -> Option<Request> {
        if buttons.a && !self.buttons.a {
            self.power = PowerTask::Now;
            self.next_internal_us = now_us;
        }
        self.buttons = buttons;
        if !idle || now_us < self.next_internal_us {
            return None;
        }
        let interval_us = config.probe_interval_us;
        let (cmd, origin) = match self.power {
            PowerTask::Now | PowerTask::Ensure { off_seen: true } => {
                (cmd::POWER_ON, Origin::PowerOn)
            }
            PowerTask::Ensure { off_seen: false } => (cmd::IS_POWER_ON, Origin::Probe),
            PowerTask::Done
                if interval_us > 0 && now_us.saturating_sub(self.last_answer_us) >= interval_us =>
            {
                (cmd::IS_POWER_ON, Origin::Probe)
            }
            PowerTask::Done => return None,
        };
        if origin == Origin::PowerOn && (self.power == PowerTask::Now || !self.retries) {
            // A press powers on once, answered or not (the user presses again); without
            // probing, the boot's power-on is tried once too.
            self.power = PowerTask::Done;
        }
        self.next_internal_us = now_us.saturating_add(interval_us.max(1));
        Some(Request {
            // Cannot fail: no data.
            frame: Frame::new(cmd, &[]).unwrap_or_default(),
            origin,
            answer: protocol_core::dialect::Answer::AsIs,
            queued_us: now_us,
            cut_through: false,
        })
    }

    /// The Atom answered the Basic's 0x12: powered or not.
    fn on_probe_answer(&mut self, now_us: u64, powered: bool) {
        if let PowerTask::Ensure { off_seen } = &mut self.power {
            if powered {
                self.power = PowerTask::Done;
            } else {
                *off_seen = true;
                // Power it on at the next idle moment, before anything else can start.
                self.next_internal_us = now_us;
            }
        }
    }

    /// An internal request of the Basic's got no answer. Without probing, the boot's question
    /// is asked once; with it, an unanswered power-on is not sent again blindly: the Basic asks
    /// first again.
    fn on_unanswered(&mut self, request: &Request) {
        if !self.retries && !matches!(request.origin, Origin::Host(_)) {
            self.power = PowerTask::Done;
        }
        if let (Origin::PowerOn, PowerTask::Ensure { off_seen }) = (request.origin, &mut self.power)
        {
            *off_seen = false;
        }
    }

    /// The Atom answered `request` with `reply` (in time or late): what it says goes into the
    /// status, and the Basic's own questions are settled.
    fn on_answer(&mut self, now_us: u64, request: &Request, reply: &Frame) {
        let status = &mut self.status;
        status.atom = AtomLink::Answering;
        self.last_answer_us = now_us;
        let done = reply.data() == [1];
        match (request.frame.cmd(), reply.data()) {
            (cmd::POWER_ON, _) => {
                // Answered either way: the Atom is alive and has decided.
                status.atom_powered = Some(done);
                if request.origin == Origin::PowerOn {
                    self.power = PowerTask::Done;
                }
            }
            (cmd::POWER_OFF, _) if done => status.atom_powered = Some(false),
            (cmd::IS_POWER_ON, &[state]) => status.atom_powered = Some(state == 1),
            _ => {}
        }
        if let (Origin::Probe, &[state]) = (request.origin, reply.data()) {
            self.on_probe_answer(now_us, state == 1);
        }
    }

    /// Watches what happened to a request at `now_us`: what the Atom said goes into the
    /// status, and the Basic's own questions are settled. Where a client's reply goes is the
    /// router's business; [`Self::on_delivery`] then hears what became of it.
    pub(crate) fn on_event(&mut self, now_us: u64, event: &Event) {
        if let (Some(Origin::Host(_)), PowerTask::Ensure { off_seen }) =
            (event.origin(), &mut self.power)
        {
            // A host request went to the Atom after it said it was off (internal requests
            // wait for an idle forwarder, so every such request ends here before the 0x10):
            // it may have started something. Ask again.
            *off_seen = false;
        }
        match event {
            Event::Reply { request, reply } => self.on_answer(now_us, request, reply),
            // Its client was given up on (and may have asked something else since): the
            // reply goes only into the status.
            Event::Late { request, reply } => {
                self.on_answer(now_us, request, reply);
                self.status.late_replies = self.status.late_replies.wrapping_add(1);
            }
            Event::Timeout(request) => {
                self.on_unanswered(request);
                let status = &mut self.status;
                status.atom = AtomLink::Silent;
                status.timeouts = status.timeouts.wrapping_add(1);
                status.last_error = Some(BasicError::ReplyTimeout {
                    cmd: request.frame.cmd(),
                });
            }
            Event::GaveUp(request) => {
                self.on_unanswered(request);
                let status = &mut self.status;
                status.collisions = status.collisions.wrapping_add(1);
                status.last_error = Some(BasicError::BusCollisions {
                    cmd: request.frame.cmd(),
                });
            }
            Event::Expired(request) => {
                self.status.last_error = Some(BasicError::QueueFull {
                    cmd: request.frame.cmd(),
                });
            }
            Event::Collision => {
                self.status.collisions = self.status.collisions.wrapping_add(1);
            }
            // A reply passed on as it arrives: its end (the reply, or the timeout) counts.
            Event::Unsolicited
            | Event::ReplyHead { .. }
            | Event::ReplyMore { .. }
            | Event::ReplyCut { .. } => {}
        }
    }

    /// What became of a client's reply the router was given to deliver.
    pub(crate) fn on_delivery(&mut self, delivery: Delivery) {
        match delivery {
            Delivery::Queued => {
                self.status.replies_forwarded = self.status.replies_forwarded.wrapping_add(1);
            }
            Delivery::NoRoom => self.error(BasicError::HostOverflow),
            // The client left while its request was on the bus.
            Delivery::Gone => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::request::{Client, LinkId};

    const DELAY_US: u64 = 1_000_000;
    const INTERVAL_US: u64 = 1_000_000;
    const NO_BUTTON: Buttons = Buttons {
        a: false,
        b: false,
        c: false,
    };
    /// The Basic's internal requests as [`next`] gives them.
    const PROBE: Option<(u8, Origin)> = Some((cmd::IS_POWER_ON, Origin::Probe));
    const POWER_ON: Option<(u8, Origin)> = Some((cmd::POWER_ON, Origin::PowerOn));
    const BUTTON_A: Buttons = Buttons {
        a: true,
        ..NO_BUTTON
    };

    fn booted(config: BasicConfig) -> Supervisor {
        let mut supervisor = Supervisor::new(&config);
        supervisor.boot(0, &config);
        supervisor
    }

    /// The internal request at `now_us` on an idle bus: its command and origin.
    fn next(supervisor: &mut Supervisor, now_us: u64, buttons: Buttons) -> Option<(u8, Origin)> {
        supervisor
            .next_internal(now_us, &BasicConfig::default(), buttons, true)
            .map(|r| (r.frame.cmd(), r.origin))
    }

    fn request(code: u8, origin: Origin) -> Request {
        Request {
            frame: Frame::new(code, &[]).unwrap(),
            origin,
            answer: protocol_core::dialect::Answer::AsIs,
            queued_us: 0,
            cut_through: false,
        }
    }

    fn answered(code: u8, origin: Origin, data: &[u8]) -> Event {
        Event::Reply {
            request: request(code, origin),
            reply: Frame::new(code, data).unwrap(),
        }
    }

    fn host() -> Origin {
        Origin::Host(Client::new(LinkId::USB, 0))
    }

    #[test]
    fn at_boot_it_asks_first_and_powers_on_only_an_atom_that_says_it_is_off() {
        let mut supervisor = booted(BasicConfig::default());
        assert_eq!(next(&mut supervisor, DELAY_US - 1, NO_BUTTON), None);
        assert_eq!(next(&mut supervisor, DELAY_US, NO_BUTTON), PROBE);
        supervisor.on_event(
            DELAY_US + 1_000,
            &answered(cmd::IS_POWER_ON, Origin::Probe, &[0]),
        );
        assert_eq!(supervisor.status.atom_powered, Some(false));
        assert_eq!(next(&mut supervisor, DELAY_US + 1_000, NO_BUTTON), POWER_ON);
        supervisor.on_event(
            DELAY_US + 2_000,
            &answered(cmd::POWER_ON, Origin::PowerOn, &[1]),
        );
        assert_eq!(supervisor.status.atom_powered, Some(true));
        assert_eq!(supervisor.status.atom, AtomLink::Answering);
        // Powered: from now on only the liveness probe, after a silence of the interval.
        assert_eq!(next(&mut supervisor, DELAY_US + 3_000, NO_BUTTON), None);
        assert_eq!(
            next(&mut supervisor, DELAY_US + 2_000 + INTERVAL_US, NO_BUTTON),
            PROBE
        );
    }

    #[test]
    fn an_atom_that_says_it_is_on_is_left_alone() {
        let mut supervisor = booted(BasicConfig::default());
        assert!(next(&mut supervisor, DELAY_US, NO_BUTTON).is_some());
        supervisor.on_event(
            DELAY_US + 500_000,
            &answered(cmd::IS_POWER_ON, Origin::Probe, &[1]),
        );
        // Not even asked again until the Atom has been silent for the interval.
        assert_eq!(
            next(&mut supervisor, DELAY_US + INTERVAL_US, NO_BUTTON),
            None
        );
        assert_eq!(
            next(&mut supervisor, DELAY_US + 500_000 + INTERVAL_US, NO_BUTTON),
            PROBE
        );
    }

    #[test]
    fn a_host_request_after_the_off_answer_makes_it_ask_again_before_powering_on() {
        let mut supervisor = booted(BasicConfig::default());
        assert!(next(&mut supervisor, DELAY_US, NO_BUTTON).is_some());
        supervisor.on_event(DELAY_US, &answered(cmd::IS_POWER_ON, Origin::Probe, &[0]));
        // A client's move reached the Atom meanwhile: it may be running now.
        supervisor.on_event(DELAY_US + 500, &answered(0x22, host(), &[1]));
        assert_eq!(next(&mut supervisor, DELAY_US + 1_000, NO_BUTTON), PROBE);
    }

    #[test]
    fn a_host_power_command_takes_the_power_out_of_the_basics_hands() {
        let mut supervisor = booted(BasicConfig::default());
        supervisor.on_host_request(cmd::POWER_OFF);
        assert_eq!(supervisor.status.host_frames, 1);
        // Only the liveness probe, never a power-on.
        assert_eq!(next(&mut supervisor, DELAY_US, NO_BUTTON), PROBE);
        supervisor.on_event(DELAY_US, &answered(cmd::IS_POWER_ON, Origin::Probe, &[0]));
        assert_eq!(
            next(&mut supervisor, DELAY_US + INTERVAL_US, NO_BUTTON),
            PROBE,
            "an Atom that is off is probed, not powered on"
        );
    }

    #[test]
    fn button_a_powers_on_once_per_press_and_a_button_held_from_boot_waits_for_a_release() {
        let config = BasicConfig {
            power_on_at_boot: false,
            ..BasicConfig::default()
        };
        let mut supervisor = booted(config);
        // Held from boot: nothing.
        assert_eq!(next(&mut supervisor, 10, BUTTON_A), None);
        assert_eq!(next(&mut supervisor, 20, NO_BUTTON), None);
        assert_eq!(next(&mut supervisor, 30, BUTTON_A), POWER_ON);
        // Unanswered and still held: once; afterwards only the probe.
        supervisor.on_event(
            60_000,
            &Event::Timeout(request(cmd::POWER_ON, Origin::PowerOn)),
        );
        assert_eq!(next(&mut supervisor, 30 + INTERVAL_US, BUTTON_A), PROBE);
        // Released and pressed again: at once.
        assert_eq!(next(&mut supervisor, 40 + INTERVAL_US, NO_BUTTON), None);
        assert_eq!(next(&mut supervisor, 50 + INTERVAL_US, BUTTON_A), POWER_ON);
    }

    #[test]
    fn it_only_counts_what_becomes_of_requests_and_replies() {
        let mut supervisor = booted(BasicConfig {
            power_on_at_boot: false,
            ..BasicConfig::default()
        });
        supervisor.on_event(1, &Event::Timeout(request(0x20, host())));
        assert_eq!(supervisor.status.atom, AtomLink::Silent);
        assert_eq!(supervisor.status.timeouts, 1);
        assert_eq!(
            supervisor.status.last_error,
            Some(BasicError::ReplyTimeout { cmd: 0x20 })
        );
        let late = Event::Late {
            request: request(0x20, host()),
            reply: Frame::new(0x20, &[1]).unwrap(),
        };
        supervisor.on_event(2, &late);
        assert_eq!(supervisor.status.late_replies, 1);
        assert_eq!(supervisor.status.atom, AtomLink::Answering);
        supervisor.on_event(3, &Event::Collision);
        supervisor.on_event(4, &Event::GaveUp(request(0x21, host())));
        assert_eq!(supervisor.status.collisions, 2);
        supervisor.on_event(5, &Event::Expired(request(0x22, host())));
        assert_eq!(
            supervisor.status.last_error,
            Some(BasicError::QueueFull { cmd: 0x22 })
        );
        supervisor.on_delivery(Delivery::Queued);
        supervisor.on_delivery(Delivery::Gone);
        assert_eq!(supervisor.status.replies_forwarded, 1);
        supervisor.on_delivery(Delivery::NoRoom);
        assert_eq!(supervisor.status.last_error, Some(BasicError::HostOverflow));
    }
}

//! Looks after the Atom and keeps the status the LCD shows: powers the Atom on after boot
//! (0x10, like the vendor transponder), probes it (0x12) when it has been silent for a while,
//! and turns the forwarder's events into replies for the host and status for the display.

use protocol_core::Frame;
use protocol_core::command::cmd;

use crate::config::BasicConfig;
use crate::forwarder::{Event, Origin, Request};
use crate::host_link::HostLink;
use crate::io::Buttons;
use crate::status::{AtomLink, BasicError, BasicStatus};

/// The supervisor's state.
#[derive(Debug)]
pub(crate) struct Supervisor {
    pub(crate) status: BasicStatus,
    /// A power-on (0x10) is owed to the Atom: at boot, or after button A.
    power_on_pending: bool,
    /// Earliest time of the next internal request.
    next_internal_us: u64,
    /// When the Atom last answered anything.
    last_answer_us: u64,
    buttons: Buttons,
}

impl Supervisor {
    pub(crate) fn new(config: &BasicConfig) -> Self {
        Self {
            status: BasicStatus {
                version_x10: config.version_x10,
                ..BasicStatus::default()
            },
            power_on_pending: config.power_on_at_boot,
            next_internal_us: 0,
            last_answer_us: 0,
            buttons: Buttons::default(),
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
        if matches!(code, cmd::POWER_OFF | cmd::RELEASE_ALL_SERVOS) {
            // The host has taken charge of the arm's power: do not power it on behind its back.
            self.power_on_pending = false;
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
            self.power_on_pending = true;
            self.next_internal_us = now_us;
        }
        self.buttons = buttons;
        if !idle || now_us < self.next_internal_us {
            return None;
        }
        let interval_us = config.probe_interval_us;
        let (cmd, origin) = if self.power_on_pending {
            (cmd::POWER_ON, Origin::PowerOn)
        } else if interval_us > 0 && now_us.saturating_sub(self.last_answer_us) >= interval_us {
            (cmd::IS_POWER_ON, Origin::Probe)
        } else {
            return None;
        };
        if interval_us == 0 {
            // Without probing, a power-on is tried once.
            self.power_on_pending = false;
        }
        self.next_internal_us = now_us.saturating_add(interval_us.max(1));
        Some(Request {
            // Cannot fail: no data.
            frame: Frame::new(cmd, &[]).unwrap_or_default(),
            origin,
            queued_us: now_us,
        })
    }

    /// Acts on what happened to a request: a host's reply goes to `host`, an internal one's
    /// only into the status.
    pub(crate) fn on_event(&mut self, now_us: u64, event: Event, host: &mut HostLink) {
        let status = &mut self.status;
        match event {
            Event::Reply { request, reply } => {
                status.atom = AtomLink::Answering;
                self.last_answer_us = now_us;
                let done = reply.data() == [1];
                match (request.frame.cmd(), reply.data()) {
                    (cmd::POWER_ON, _) => {
                        // Answered either way: the Atom is alive and has decided.
                        status.atom_powered = Some(done);
                        self.power_on_pending = false;
                    }
                    (cmd::POWER_OFF, _) if done => status.atom_powered = Some(false),
                    (cmd::IS_POWER_ON, &[state]) => status.atom_powered = Some(state == 1),
                    _ => {}
                }
                if request.origin == Origin::Host {
                    if host.send_frame(&reply) {
                        status.replies_forwarded = status.replies_forwarded.wrapping_add(1);
                    } else {
                        status.last_error = Some(BasicError::HostOverflow);
                    }
                }
            }
            Event::Timeout(request) => {
                status.atom = AtomLink::Silent;
                status.timeouts = status.timeouts.wrapping_add(1);
                status.last_error = Some(BasicError::ReplyTimeout {
                    cmd: request.frame.cmd(),
                });
            }
            Event::GaveUp(request) => {
                status.collisions = status.collisions.wrapping_add(1);
                status.last_error = Some(BasicError::BusCollisions {
                    cmd: request.frame.cmd(),
                });
            }
            Event::Expired(request) => {
                status.last_error = Some(BasicError::QueueFull {
                    cmd: request.frame.cmd(),
                });
            }
            Event::Collision => status.collisions = status.collisions.wrapping_add(1),
            Event::Unsolicited => {}
        }
    }
}

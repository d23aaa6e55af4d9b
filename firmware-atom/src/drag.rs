//! Drag teaching (0xF1..0xF5): while recording, every joint's encoder position and speed are
//! taken from the servo bank's state reads at a fixed rate ([`SAMPLE_PERIOD_US`]) into a
//! bounded buffer ([`CAPACITY`] points), which the host then reads back one point per request,
//! in order, and replays with set encoders drag (0x3E), set encoders or send angles.
//!
//! Meant for an arm whose joints are released (free mode, release all servos) and moved by
//! hand, but it records whatever the joints do. A full buffer ends the recording by itself: the
//! length then reads [`CAPACITY`], and a new start is refused the same way (it answers the
//! length and records nothing) until the points are cleared.

use protocol_core::command::{DragPoint, MAX_DRAG_SPEED};
use protocol_core::units::Steps;

use crate::bank::ServoBank;
use crate::config::JOINTS;

/// Time between two recorded points, us: 50 ms (20 points a second), finer than a hand moves
/// the arm and as fine as pymycobot's own record-and-replay demo samples (one get encoders and
/// get servo speeds round trip, 30..50 ms).
pub const SAMPLE_PERIOD_US: u64 = 50_000;

/// Points the recording holds: 1 000, 50 s at [`SAMPLE_PERIOD_US`] (24 bytes each, 24 kB).
pub const CAPACITY: usize = 1_000;

/// The drag-teaching recorder. See the [module doc](self).
#[derive(Clone, Debug)]
pub struct DragRecorder {
    points: heapless::Vec<DragPoint, CAPACITY>,
    recording: bool,
    /// When the next point is due, us.
    next_sample_us: u64,
    /// The next point drag get record data (0xF3) answers.
    read_next: usize,
}

impl Default for DragRecorder {
    fn default() -> Self {
        Self::new()
    }
}

impl DragRecorder {
    /// A recorder holding no points, not recording.
    pub fn new() -> Self {
        Self {
            points: heapless::Vec::new(),
            recording: false,
            next_sample_us: 0,
            read_next: 0,
        }
    }

    /// Starts recording (0xF1) at `now_us`, after the points already held, and rewinds the
    /// reading; the first point is taken now. Returns the points held. A full buffer does not
    /// start (it answers [`CAPACITY`]).
    pub fn start(&mut self, now_us: u64) -> u16 {
        self.read_next = 0;
        self.recording = !self.points.is_full();
        self.next_sample_us = now_us;
        self.recorded()
    }

    /// Ends the recording (0xF2); returns the points held.
    pub fn end(&mut self) -> u16 {
        self.recording = false;
        self.recorded()
    }

    /// The points held (0xF4).
    pub fn recorded(&self) -> u16 {
        u16::try_from(self.points.len()).unwrap_or(u16::MAX)
    }

    /// True while recording (until ended, or until the buffer filled up).
    pub fn is_recording(&self) -> bool {
        self.recording
    }

    /// Forgets every point and stops recording (0xF5); returns the points held now, 0.
    pub fn clear(&mut self) -> u16 {
        self.points.clear();
        self.recording = false;
        self.read_next = 0;
        self.recorded()
    }

    /// The next point in recording order (0xF3); `None` after the last one, and the next call
    /// starts again from the first.
    pub fn next_point(&mut self) -> Option<DragPoint> {
        let point = self.points.get(self.read_next).copied();
        self.read_next = if point.is_some() {
            self.read_next + 1
        } else {
            0
        };
        point
    }

    /// Takes a point from the joints' last state reads if one is due at `now_us`. Points are
    /// due every [`SAMPLE_PERIOD_US`]; after a stall (a main loop that did not run for longer
    /// than that) the next is taken at once and the rate resumes from there.
    pub fn poll(&mut self, now_us: u64, bank: &ServoBank) {
        if !self.recording || now_us < self.next_sample_us {
            return;
        }
        let on_time = self.next_sample_us + SAMPLE_PERIOD_US;
        self.next_sample_us = if now_us >= on_time {
            now_us + SAMPLE_PERIOD_US
        } else {
            on_time
        };
        let point = DragPoint {
            encoders: core::array::from_fn(|j| bank.health(j).map_or(Steps(0), |h| h.position)),
            speeds_steps_per_s: core::array::from_fn(|j| {
                bank.health(j).map_or(0, |h| {
                    // What the servo reports: 0 for a joint at rest. Set encoders drag refuses
                    // 0 (the servo would race), so a replay through it gives such a joint a speed.
                    h.speed_steps_per_s.saturating_abs().min(MAX_DRAG_SPEED)
                })
            }),
        };
        if self.points.push(point).is_err() || self.points.is_full() {
            self.recording = false;
        }
    }
}

const _: () = assert!(JOINTS == 6, "a drag point holds six joints");
const _: () = assert!(
    CAPACITY <= i16::MAX as usize,
    "the length is answered as an int16"
);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::AtomConfig;
    use crate::settings::Settings;

    fn bank() -> ServoBank {
        ServoBank::new(&Settings::new(AtomConfig::default()))
    }

    #[test]
    fn points_come_at_the_sample_rate_and_read_back_in_order() {
        let bank = bank();
        let mut drag = DragRecorder::new();
        assert_eq!(drag.start(1_000), 0);
        for t in (1_000..=1_000 + 10 * SAMPLE_PERIOD_US).step_by(1_000) {
            drag.poll(t, &bank);
        }
        // At the start and every 50 ms after it, both ends included.
        assert_eq!(drag.recorded(), 11);
        assert_eq!(drag.end(), 11);
        drag.poll(10_000_000, &bank);
        assert_eq!(drag.recorded(), 11, "nothing recorded after the end");
        for _ in 0..11 {
            let p = drag.next_point().expect("a point");
            assert_eq!(p.encoders, [Steps(2048); 6]);
        }
        assert_eq!(drag.next_point(), None);
        assert!(drag.next_point().is_some(), "reading starts over");
        assert_eq!(drag.clear(), 0);
        assert_eq!(drag.next_point(), None);
    }

    #[test]
    fn a_full_buffer_ends_the_recording_and_refuses_a_new_start() {
        let bank = bank();
        let mut drag = DragRecorder::new();
        drag.start(0);
        let mut t = 0;
        while drag.is_recording() {
            drag.poll(t, &bank);
            t += SAMPLE_PERIOD_US;
            assert!(t < 2 * CAPACITY as u64 * SAMPLE_PERIOD_US, "never filled");
        }
        assert_eq!(usize::from(drag.recorded()), CAPACITY);
        assert_eq!(usize::from(drag.start(t)), CAPACITY);
        assert!(!drag.is_recording());
        assert_eq!(drag.clear(), 0);
        assert_eq!(drag.start(t), 0);
        assert!(drag.is_recording());
    }

    #[test]
    fn a_stalled_loop_takes_the_next_point_at_once_without_a_burst() {
        let bank = bank();
        let mut drag = DragRecorder::new();
        drag.start(0);
        drag.poll(0, &bank);
        drag.poll(1_000_000, &bank);
        drag.poll(1_000_000 + 1_000, &bank);
        assert_eq!(drag.recorded(), 2);
        drag.poll(1_000_000 + SAMPLE_PERIOD_US, &bank);
        assert_eq!(drag.recorded(), 3);
    }
}

//! The accessory hobby servo at the end of the arm: pymycobot's `move_round` (0xD4, "drive the
//! 9g steering gear clockwise for one revolution") and `set_four_pieces_zero` (0xD7, "set the
//! zero position of the four-piece motor").
//!
//! Both belong to the vendor's Connect-4 ("four pieces") kit: a 9 g continuous-rotation servo
//! on the end of the arm, plugged into the Atom's Grove port (GPIO26), whose turn pushes one
//! piece out of the kit's dispenser (the kit's `drop_piece` is one `move_round`). It takes the
//! standard hobby-servo signal, a pulse every 20 ms: [`STOP_PULSE_US`] holds it still,
//! [`TURN_PULSE_US`] turns it clockwise at full speed, and one revolution takes [`TURN_US`].
//! `move_round` turns it for that long (each call one more revolution) and then stops it;
//! `set_four_pieces_zero` stops it where it is, at its zero (neutral) pulse, ending any turn.

use crate::error::AtomError;
use crate::io::AtomIo;

/// Pulse that holds a continuous-rotation hobby servo still (its neutral), microseconds.
pub const STOP_PULSE_US: u16 = 1_500;

/// Pulse that turns it clockwise at full speed, microseconds (500 us short of neutral).
pub const TURN_PULSE_US: u16 = 1_000;

/// Time one revolution takes at full speed, microseconds: 0.55 s, an SG90-class
/// continuous-rotation servo's 110 rpm at 5 V.
pub const TURN_US: u64 = 550_000;

/// The accessory servo. See the [module doc](self).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Dispenser {
    /// When the turn in progress ends, us.
    turning_until_us: Option<u64>,
}

impl Dispenser {
    /// Turns the servo clockwise for one more revolution from `now_us` (0xD4). Fails if the
    /// board has no accessory servo output.
    pub fn turn<I: AtomIo>(&mut self, now_us: u64, io: &mut I) -> Result<(), AtomError> {
        if !io.set_accessory_servo(Some(TURN_PULSE_US)) {
            return Err(AtomError::Invalid);
        }
        let from = self.turning_until_us.map_or(now_us, |t| t.max(now_us));
        self.turning_until_us = Some(from + TURN_US);
        Ok(())
    }

    /// Stops the servo at its zero (neutral) pulse, ending any turn (0xD7); false if the board
    /// has no accessory servo output.
    pub fn zero<I: AtomIo>(&mut self, io: &mut I) -> bool {
        self.turning_until_us = None;
        io.set_accessory_servo(Some(STOP_PULSE_US))
    }

    /// Ends a turn whose time is up at `now_us`.
    pub fn poll<I: AtomIo>(&mut self, now_us: u64, io: &mut I) {
        if self.turning_until_us.is_some_and(|t| now_us >= t) {
            self.zero(io);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::RecordingIo;

    #[test]
    fn a_turn_lasts_one_revolution_per_request_then_the_servo_stops() {
        let mut io = RecordingIo::default();
        let mut d = Dispenser::default();
        assert_eq!(io.accessory_servo_pulse_us, None, "no pulses at boot");
        assert_eq!(d.turn(1_000, &mut io), Ok(()));
        assert_eq!(io.accessory_servo_pulse_us, Some(TURN_PULSE_US));
        d.poll(1_000 + TURN_US / 2, &mut io);
        // A second request half way adds a revolution.
        assert_eq!(d.turn(1_000 + TURN_US / 2, &mut io), Ok(()));
        d.poll(1_000 + 2 * TURN_US - 1, &mut io);
        assert_eq!(io.accessory_servo_pulse_us, Some(TURN_PULSE_US));
        d.poll(1_000 + 2 * TURN_US, &mut io);
        assert_eq!(io.accessory_servo_pulse_us, Some(STOP_PULSE_US));
    }

    #[test]
    fn zero_stops_a_turn_at_once() {
        let mut io = RecordingIo::default();
        let mut d = Dispenser::default();
        assert_eq!(d.turn(0, &mut io), Ok(()));
        assert!(d.zero(&mut io));
        assert_eq!(io.accessory_servo_pulse_us, Some(STOP_PULSE_US));
    }
}

//! Timing of the links, shared by both firmwares and the virtual robot so that every station
//! on the one shared bus follows the same rules. All durations in microseconds.
//!
//! The shared bus has no arbiter. The rules that keep it working:
//! * The Atom is the only station that talks to servos. A servo answers within
//!   [`SERVO_TURNAROUND_MAX_US`] of the end of the instruction addressed to it.
//! * The Basic transmits a host frame only after the wire has been silent for
//!   [`BUS_QUIET_BEFORE_SEND_US`], longer than any servo turnaround, so it never talks into a
//!   transaction that is waiting for a servo's answer.
//! * Between two servo transactions the Atom leaves the wire silent for at least
//!   [`ATOM_TRANSACTION_GAP_US`], longer than the Basic's quiet time, so the Basic always gets
//!   its turn. A host reply is sent in that gap, before the next transaction.
//! * A station that does transmit over another one sees its echo differ (the Basic) or a bad
//!   checksum / no answer (the Atom) and retries.
//! * Every station hears the wire through one [`crate::listener::Listener`]: a frame or packet
//!   interrupted by [`BUS_FRAME_GAP_US`] / [`BUS_PACKET_GAP_US`] of silence was cut short, and
//!   its own echo is back within [`ECHO_GRACE_US`] or not coming.

/// Baud rate of the shared bus (Basic, Atom, servos).
pub const BUS_BAUD: u32 = 1_000_000;
/// Baud rate of the host links (USB serial of the Basic and of the Atom).
pub const HOST_BAUD: u32 = 115_200;

/// Bits on the wire per byte: start, 8 data, stop (8N1).
pub const BITS_PER_BYTE: u32 = 10;

/// Wire time of `bytes` bytes at `baud`, in nanoseconds.
pub const fn wire_time_ns(bytes: u32, baud: u32) -> u64 {
    if baud == 0 {
        return u64::MAX;
    }
    (bytes as u64 * BITS_PER_BYTE as u64 * 1_000_000_000).div_ceil(baud as u64)
}

/// Wire time of `bytes` bytes at `baud`, in whole microseconds, rounded up.
pub const fn wire_time_us(bytes: u32, baud: u32) -> u64 {
    wire_time_ns(bytes, baud).div_ceil(1000)
}

/// Longest a servo takes from the end of an instruction to the start of its answer.
pub const SERVO_TURNAROUND_MAX_US: u64 = 40;
/// Silence the Basic waits for before it transmits onto the bus.
pub const BUS_QUIET_BEFORE_SEND_US: u64 = 60;
/// Silence the Atom leaves between two servo transactions.
pub const ATOM_TRANSACTION_GAP_US: u64 = 100;
/// A gap this long inside a host frame on the bus means it was cut short.
pub const BUS_FRAME_GAP_US: u64 = 200;
/// A gap this long inside a servo packet on the bus means it was cut short, for the Atom
/// reading servo answers: a servo (like the Atom) writes a packet in one go, back to back, so
/// four byte times of silence inside one never happen on a healthy wire. (A tool's packet that
/// the Basic relays in transparent mode arrives byte by byte at host speed; the servos, which
/// must take those whole, wait longer.)
pub const BUS_PACKET_GAP_US: u64 = 40;
/// How long after the last byte of a transmission has left the wire its echo may still come
/// back, for a station that hears itself: three byte times at 1 Mbaud.
///
/// The UART hands a byte over at its stop bit; the station reads it at its next poll (the
/// Basic budgets one byte time for that), and a busy loop may take one byte time more. The
/// Basic used 20 us and the Atom 30 us; one value now serves both, and it is the longer one,
/// because the two ways to be wrong are not alike: a window that closes too early turns a late
/// echo into a "missing" echo and into someone else's bytes (the Atom would decode its own
/// reply as a request, a raw tool in transparent mode would get its own bytes back), while one
/// that closes 10 us later only delays the verdict on an echo that really is missing. It is
/// still shorter than [`BUS_QUIET_BEFORE_SEND_US`], so the verdict on one transmission is in
/// before the Basic may start the next.
pub const ECHO_GRACE_US: u64 = 30;
/// A gap this long inside a host frame on a 115200 link means it was cut short (Modbus-RTU
/// style; senders write a frame in one go).
pub const HOST_FRAME_GAP_US: u64 = 2_000;
/// The reply deadline pymycobot gives a command before it resends (`protocol.md` section 3).
pub const HOST_REPLY_DEADLINE_US: u64 = 500_000;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn byte_times() {
        assert_eq!(wire_time_ns(1, BUS_BAUD), 10_000);
        assert_eq!(wire_time_us(5, HOST_BAUD), 435);
        const { assert!(BUS_QUIET_BEFORE_SEND_US > SERVO_TURNAROUND_MAX_US) };
        const { assert!(ATOM_TRANSACTION_GAP_US > BUS_QUIET_BEFORE_SEND_US) };
        const { assert!(ECHO_GRACE_US < BUS_QUIET_BEFORE_SEND_US) };
    }
}

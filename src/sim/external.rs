//! Boards that run outside the simulation (an emulated chip running the real image): their bus
//! UART is a byte stream, and here they are stations on the simulated bus like any other.
//!
//! * [`FrameGate`]: what a board sends arrives in chunks, whenever the emulator and the socket
//!   pass it on; a real UART sends a frame back to back, and the bus ends a frame at a 200 us
//!   gap. The gate holds bytes until they make a whole frame (a host frame `FE FE LEN ...` or a
//!   servo packet `FF FF ID LEN ...`) and lets it onto the wire in one piece; bytes that make
//!   no frame pass once nothing more has come for [`STALE_AFTER_NS`].
//! * The other way, the same: what a board hears is handed to its socket a whole frame or
//!   packet at a time. The loop that writes the sockets runs on a tick, and a servo answer
//!   handed over as its bytes come off the wire went in two or three chunks; the emulator
//!   passes each chunk to the UART at the baud rate, but a late chunk left a gap inside the
//!   answer, and the firmware cuts a servo packet short after 40 us of silence
//!   (`BUS_PACKET_GAP_US`): the answer was dropped as a fragment. On a real wire a packet's
//!   bytes come back to back. (Found on the emulated C3 Atom: 18 % of its state reads got no
//!   answer it could take, with every answer whole on the simulated wire and no checksum
//!   error.)
//! * [`EmulatedArm`]: the simulated bus and seven servos with external boards attached. Each
//!   hears every other station's bytes, but not its own: on the real boards TX and RX are tied
//!   and the echo ends 30 us after the byte at the latest ([`ECHO_GRACE_US`]), which no echo
//!   passed back through an emulator's socket can meet (it comes 100 us and more late, and a
//!   late echo is taken for another station's bytes). Without it the firmware finds the line
//!   does not echo, as on a board wired without the tie, and serves it as such. Time advances
//!   in [`EmulatedArm::run_until`].
//!
//!
//!   A board decides to transmit from the line as it saw it, but its bytes reach the simulated
//!   wire after the emulator's and the socket's delay, by which time the line may be busy. So a
//!   board's frame starts only when its own rule for a free line holds on the wire then: the
//!   Basic's [`BUS_QUIET_BEFORE_SEND_US`] of silence, the Atom's (the bus's master) no byte
//!   under way. Without it the Basic's requests ran into the Atom's servo polling and were lost.
//!
//! [`ECHO_GRACE_US`]: protocol_core::timing::ECHO_GRACE_US
//! [`BUS_QUIET_BEFORE_SEND_US`]: protocol_core::timing::BUS_QUIET_BEFORE_SEND_US

use protocol_core::BytePort;

use super::contact::Obstacle;
use super::reply_faults::ReplyFault;
use super::robot::SERVO_IDS;
use super::servo::SimServo;
use super::wire::{Bus, BusByte, HeardByte, StationId};
use firmware_atom::AtomConfig;
use sim_hw::ServoChain;

/// How long the bytes of an unfinished frame wait for the rest before they go on the wire as
/// they are (garbage the board sent, or a frame cut short): far longer than any chunking of a
/// frame by the emulator, far shorter than any reply deadline's retry.
pub const STALE_AFTER_NS: u64 = 2_000_000;

/// Most bytes a gate holds: a frame is at most 258 bytes; beyond this the oldest go at once.
const GATE_BYTES: usize = 1024;

/// Collects what a board sends and releases whole frames. See the [module doc](self).
#[derive(Clone, Debug, Default)]
pub struct FrameGate {
    held: Vec<u8>,
    last_byte_ns: u64,
}

impl FrameGate {
    /// An empty gate.
    pub fn new() -> Self {
        Self::default()
    }

    /// Bytes the board sent, arrived at `now_ns`.
    pub fn push(&mut self, now_ns: u64, bytes: &[u8]) {
        if !bytes.is_empty() {
            self.held.extend_from_slice(bytes);
            self.last_byte_ns = now_ns;
        }
    }

    /// Appends to `out` what may go on the wire at `now_ns`: the first whole frame, the bytes
    /// around it that belong to none, and everything once it is stale. A frame behind it waits
    /// for the next call (the line must be free for it again: see [`EmulatedArm`]).
    pub fn release(&mut self, now_ns: u64, out: &mut Vec<u8>) {
        let stale = now_ns.saturating_sub(self.last_byte_ns) >= STALE_AFTER_NS;
        let mut ready = 0;
        let mut whole = false;
        loop {
            let rest = self.held.get(ready..).unwrap_or_default();
            match frame_extent(rest) {
                // Whole frames go one at a time however long they waited (staleness is for
                // a frame cut short, not for one held behind another).
                Extent::Whole(_) if whole => break,
                Extent::Whole(n) => {
                    ready += n;
                    whole = true;
                }
                Extent::NotAFrame(n) => ready += n,
                Extent::Partial if whole => break,
                Extent::Partial if stale || rest.len() > GATE_BYTES => ready = self.held.len(),
                Extent::Partial | Extent::Empty => break,
            }
        }
        out.extend(self.held.drain(..ready));
    }

    /// Whether any bytes are held.
    pub fn holds(&self) -> bool {
        !self.held.is_empty()
    }

    /// When held bytes go stale, if any are held.
    pub fn next_event_ns(&self) -> Option<u64> {
        (!self.held.is_empty()).then(|| self.last_byte_ns.saturating_add(STALE_AFTER_NS))
    }
}

/// What the start of a byte stream is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Extent {
    /// Nothing at all.
    Empty,
    /// A whole host frame or servo packet of this many bytes.
    Whole(usize),
    /// The start of a frame whose rest has not come yet.
    Partial,
    /// This many bytes before anything that could start a frame.
    NotAFrame(usize),
}

fn frame_extent(bytes: &[u8]) -> Extent {
    // Host frames: FE FE LEN CMD DATA FA, LEN counting from CMD to FA. Servo packets:
    // FF FF ID LEN INSTR PARAMS CHECKSUM, LEN counting from INSTR to the checksum.
    let (len_at, extra) = match bytes {
        [] => return Extent::Empty,
        [0xFE] | [0xFF] => return Extent::Partial,
        [0xFE, 0xFE, ..] => (2, 3),
        [0xFF, 0xFF, ..] => (3, 4),
        _ => {
            let start = bytes
                .iter()
                .skip(1)
                .position(|&b| b == 0xFE || b == 0xFF)
                .map_or(bytes.len(), |i| i + 1);
            return Extent::NotAFrame(start);
        }
    };
    match bytes.get(len_at) {
        None => Extent::Partial,
        Some(&len) => {
            let total = usize::from(len) + extra;
            if bytes.len() >= total {
                Extent::Whole(total)
            } else {
                Extent::Partial
            }
        }
    }
}

/// A board outside the simulation, as a station on the bus.
#[derive(Clone, Debug)]
struct ExternalBoard {
    station: StationId,
    /// Silence its frames wait for on the wire, in ns (see the [module doc](self)).
    quiet_before_send_ns: u64,
    gate: FrameGate,
    /// What the board's UART receives, held until it makes a whole frame or packet.
    received: FrameGate,
}

/// The simulated bus and servos serving boards that run elsewhere. See the [module doc](self).
#[derive(Clone, Debug)]
pub struct EmulatedArm {
    now_ns: u64,
    bus: Bus,
    servos: ServoChain,
    boards: Vec<ExternalBoard>,
    heard: Vec<HeardByte>,
    frame: Vec<u8>,
    /// Instants simulated so far (for the tests: time must not crawl).
    steps: u64,
}

/// One of the boards of an [`EmulatedArm`], in the order they were attached.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BoardId(usize);

impl EmulatedArm {
    /// The bus with the seven servos at `initial_position_steps`, no board yet, at time 0.
    pub fn new(seed: u64, initial_position_steps: u16) -> Self {
        let mut bus = Bus::mycobot(seed);
        let mut servos = ServoChain::new();
        for &id in &SERVO_IDS {
            servos.attach(&mut bus, SimServo::new(id, initial_position_steps));
        }
        bus.set_tap(true);
        Self {
            now_ns: 0,
            bus,
            servos,
            boards: Vec::new(),
            heard: Vec::new(),
            frame: Vec::new(),
            steps: 0,
        }
    }

    /// Attaches a board whose frames wait for `quiet_before_send_us` of silence on the wire; it
    /// does not hear its own transmissions (see the [module doc](self)).
    pub fn attach_board(&mut self, quiet_before_send_us: u64) -> BoardId {
        let station = self.bus.attach(false);
        self.boards.push(ExternalBoard {
            station,
            quiet_before_send_ns: quiet_before_send_us.saturating_mul(1_000),
            gate: FrameGate::new(),
            received: FrameGate::new(),
        });
        BoardId(self.boards.len() - 1)
    }

    /// Puts `obstacle` in its joint's way, with the joints mapped onto servos as the Atom's
    /// default configuration does (the emulated Atom runs it); `false` if there is no such servo.
    pub fn add_obstacle(&mut self, obstacle: Obstacle) -> bool {
        obstacle.place(&mut self.servos, &AtomConfig::default())
    }

    /// Makes a servo's answers late or lost ([`ReplyFault`]); `false` if there is no such
    /// servo.
    pub fn add_reply_fault(&mut self, fault: ReplyFault) -> bool {
        fault.apply(&mut self.servos)
    }

    /// Records every byte that completes on the wire from now on (`true`), for
    /// [`EmulatedArm::take_trace`]; off by default.
    pub fn set_tracing(&mut self, on: bool) {
        self.bus.set_tracing(on);
    }

    /// Bytes that completed on the wire since the last call, in end order (empty unless
    /// tracing is on).
    pub fn take_trace(&mut self) -> Vec<BusByte> {
        self.bus.take_trace()
    }

    /// The bus station of `board` (the servos are stations 0 to 6, the boards follow in the
    /// order they were attached).
    pub fn station(&self, board: BoardId) -> Option<StationId> {
        self.boards.get(board.0).map(|b| b.station)
    }

    /// Virtual time, in microseconds.
    pub fn now_us(&self) -> u64 {
        self.now_ns / 1_000
    }

    /// Bytes `board` sent on its bus UART, read from its socket at `arrived_us` (virtual time,
    /// at least [`EmulatedArm::now_us`]); they go on the wire as whole frames, from the arm's
    /// present instant on. An unfinished frame goes stale [`STALE_AFTER_NS`] after its bytes
    /// arrived, not after the arm's last step: the loop that reads the sockets sleeps up to 5 ms
    /// while the line is quiet, so the last step can be that old when a board starts a frame,
    /// and counted from it the first chunk was stale at once and went on the wire alone (a
    /// backup's reply, after the Atom's 60 ms of quiet flash work, reached the Basic as `FE`
    /// and, 1.5 ms later, `FE 03 EA 00 FA`: cut by the 200 us gap, dropped, never answered).
    pub fn board_sent(&mut self, board: BoardId, arrived_us: u64, bytes: &[u8]) {
        let arrived_ns = arrived_us.saturating_mul(1_000).max(self.now_ns);
        if let Some(b) = self.boards.get_mut(board.0) {
            b.gate.push(arrived_ns, bytes);
        }
    }

    /// Appends to `out` what `board`'s bus UART received so far, in whole frames and packets
    /// (bytes that make none once nothing more came for [`STALE_AFTER_NS`]).
    pub fn board_received(&mut self, board: BoardId, out: &mut Vec<u8>) {
        if let Some(b) = self.boards.get_mut(board.0) {
            loop {
                let before = out.len();
                b.received.release(self.now_ns, out);
                if out.len() == before {
                    break;
                }
            }
        }
    }

    /// Whether anything is under way on the bus: a byte, an answer due, held bytes.
    pub fn busy(&self) -> bool {
        self.bus.busy()
            || self.servos.next_event_ns().is_some()
            || self
                .boards
                .iter()
                .any(|b| b.gate.holds() || b.received.holds())
    }

    /// Advances virtual time to `t_us`.
    pub fn run_until(&mut self, t_us: u64) {
        let target = t_us.saturating_mul(1_000);
        self.step(self.now_ns);
        while self.now_ns < target {
            let mut next = target;
            let events = [self.bus.next_event_ns(), self.servos.next_event_ns()];
            // A held frame may go when its board's quiet time on the wire is over, or when it
            // goes stale. Only instants still ahead count: one already past waits for the line
            // to be free, and that happens at a bus event (stepping to a past instant would
            // crawl one nanosecond at a time while the line stays busy).
            let last_activity = self.bus.last_activity_ns();
            let gates = self.boards.iter().filter(|b| b.gate.holds()).flat_map(|b| {
                [
                    b.gate.next_event_ns(),
                    Some(last_activity + b.quiet_before_send_ns),
                ]
            });
            for t in events.into_iter().chain(gates).flatten() {
                if t > self.now_ns {
                    next = next.min(t);
                }
            }
            self.step(next);
        }
    }

    /// One instant: bytes that ended arrive, servos and boards hear them, answers and whole
    /// frames start.
    fn step(&mut self, now_ns: u64) {
        self.now_ns = now_ns;
        self.steps += 1;
        self.bus.deliver(now_ns);
        self.bus.take_heard(&mut self.heard);
        for heard in self.heard.drain(..) {
            self.servos.hear(&heard);
        }
        self.servos.transmit_due(now_ns, &mut self.bus);
        // A servo's answer due: no board starts in the turnaround before it. On the wire the
        // Atom sends its next packet only after the answer (or its deadline), but a board
        // whose emulator or socket was held up hands over several packets at once, and sent
        // back to back each would run into the answer to the one before.
        let answer_due = self.servos.next_event_ns().is_some();
        for board in &mut self.boards {
            let quiet_ns = now_ns.saturating_sub(self.bus.last_activity_ns());
            let line_free =
                !self.bus.busy() && !answer_due && quiet_ns >= board.quiet_before_send_ns;
            let Some(mut port) = self.bus.port(board.station) else {
                continue;
            };
            self.frame.clear();
            while let Some(byte) = port.read_byte() {
                self.frame.push(byte);
            }
            board.received.push(now_ns, &self.frame);
            if line_free {
                self.frame.clear();
                board.gate.release(now_ns, &mut self.frame);
                port.write(&self.frame);
            }
        }
        self.bus.start_transmissions(now_ns);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn released(gate: &mut FrameGate, now_ns: u64) -> Vec<u8> {
        let mut out = Vec::new();
        gate.release(now_ns, &mut out);
        out
    }

    #[test]
    fn a_frame_in_chunks_goes_out_whole_and_garbage_passes() {
        let mut gate = FrameGate::new();
        gate.push(0, &[0xFE, 0xFE, 0x02]);
        assert!(
            released(&mut gate, 10).is_empty(),
            "half a host frame waits"
        );
        gate.push(20, &[0x10, 0xFA, 0x01, 0x02, 0xFF, 0xFF, 0x01]);
        assert_eq!(
            released(&mut gate, 30),
            [0xFE, 0xFE, 0x02, 0x10, 0xFA, 0x01, 0x02],
            "the frame and the garbage after it go; the packet's start waits"
        );
        gate.push(40, &[0x04, 0x02, 0x38, 0x02, 0xBE]);
        assert_eq!(
            released(&mut gate, 50),
            [0xFF, 0xFF, 0x01, 0x04, 0x02, 0x38, 0x02, 0xBE]
        );
        assert_eq!(gate.next_event_ns(), None);
    }

    #[test]
    fn an_unfinished_frame_goes_as_it_is_once_stale() {
        let mut gate = FrameGate::new();
        gate.push(1_000, &[0xFE, 0xFE, 0x10, 0x20]);
        assert_eq!(gate.next_event_ns(), Some(1_000 + STALE_AFTER_NS));
        assert!(released(&mut gate, STALE_AFTER_NS).is_empty());
        assert_eq!(
            released(&mut gate, 1_000 + STALE_AFTER_NS),
            [0xFE, 0xFE, 0x10, 0x20]
        );
    }

    #[test]
    fn a_board_hears_the_servo_answer_to_its_frame_and_not_its_echo() {
        let mut arm = EmulatedArm::new(1, 2048);
        let atom = arm.attach_board(0);
        arm.run_until(100);
        // READ servo 1, present position (0x38), 2 bytes.
        let read = [0xFF, 0xFF, 0x01, 0x04, 0x02, 0x38, 0x02, 0xBE];
        arm.board_sent(atom, 100, &read[..3]);
        arm.run_until(150);
        arm.board_sent(atom, 150, &read[3..]);
        arm.run_until(2_000);
        let mut heard = Vec::new();
        arm.board_received(atom, &mut heard);
        assert_eq!(heard.get(..5), Some(&[0xFF, 0xFF, 0x01, 0x04, 0x00][..]));
        assert_eq!(heard.get(5..7), Some(&[0x00, 0x08][..]), "position 2048");
        assert_eq!(heard.len(), 8, "the answer alone: {heard:02X?}");
        assert!(!arm.busy());
    }

    #[test]
    fn a_board_hears_a_servo_answer_in_one_piece_however_often_it_is_asked() {
        let mut arm = EmulatedArm::new(1, 2048);
        let atom = arm.attach_board(0);
        arm.run_until(100);
        // READ servo 1's state (0x28, 31 bytes): a 37-byte answer, 370 us on the wire.
        arm.board_sent(atom, 100, &[0xFF, 0xFF, 0x01, 0x04, 0x02, 0x28, 0x1F, 0xB1]);
        let mut chunks = Vec::new();
        for t in (150..2_000).step_by(50) {
            arm.run_until(t);
            let mut heard = Vec::new();
            arm.board_received(atom, &mut heard);
            if !heard.is_empty() {
                chunks.push(heard);
            }
        }
        assert_eq!(chunks.len(), 1, "in pieces: {chunks:02X?}");
        assert_eq!(chunks.first().map(Vec::len), Some(37));
    }

    #[test]
    fn a_frame_held_while_the_line_stays_busy_costs_no_extra_steps() {
        let mut arm = EmulatedArm::new(1, 2048);
        let atom = arm.attach_board(0);
        let basic = arm.attach_board(60);
        // The Basic's frame goes stale while the Atom keeps the line busy with 40 us gaps.
        arm.board_sent(basic, 0, &[0xFE, 0xFE, 0x02]);
        let ping = [0xFF, 0xFF, 0x09, 0x02, 0x01, 0xF3]; // no servo 9: nobody answers
        let mut t = 0;
        while t < STALE_AFTER_NS / 1_000 + 2_000 {
            arm.board_sent(atom, t, &ping);
            t += 100; // 60 us of packet, 40 us of gap
            arm.run_until(t);
        }
        let steps_per_us = arm.steps as f64 / t as f64;
        assert!(steps_per_us < 1.0, "{steps_per_us} steps per us");
    }

    #[test]
    fn a_frame_waits_for_the_boards_quiet_line_on_the_wire() {
        let mut arm = EmulatedArm::new(1, 2048);
        let atom = arm.attach_board(0);
        let basic = arm.attach_board(60);
        arm.run_until(100);
        arm.board_sent(atom, 100, &[0xFF, 0xFF, 0x01, 0x04, 0x02, 0x38, 0x02, 0xBE]);
        arm.run_until(120);
        // The Basic's frame arrives while the Atom's packet is on the wire.
        let get_angles = [0xFE, 0xFE, 0x02, 0x20, 0xFA];
        arm.board_sent(basic, 120, &get_angles);
        arm.run_until(3_000);
        let mut atom_heard = Vec::new();
        arm.board_received(atom, &mut atom_heard);
        let answer = [0xFF, 0xFF, 0x01, 0x04, 0x00, 0x00, 0x08, 0xF2];
        assert_eq!(
            atom_heard.get(..8),
            Some(&answer[..]),
            "the servo's answer, ungarbled"
        );
        assert_eq!(
            atom_heard.get(8..),
            Some(&get_angles[..]),
            "then the Basic's frame"
        );
    }

    #[test]
    fn a_frame_started_after_a_quiet_spell_goes_on_the_wire_whole() {
        let mut arm = EmulatedArm::new(1, 2048);
        let atom = arm.attach_board(0);
        let basic = arm.attach_board(60);
        arm.run_until(100);
        // The line was quiet, the loop slept 5 ms; the Atom's reply comes in two chunks.
        let reply = [0xFE, 0xFE, 0x03, 0xEA, 0x00, 0xFA];
        arm.board_sent(atom, 5_100, &reply[..1]);
        arm.run_until(5_100);
        arm.run_until(5_300);
        let mut heard = Vec::new();
        arm.board_received(basic, &mut heard);
        assert!(heard.is_empty(), "the first byte went alone: {heard:02X?}");
        arm.board_sent(atom, 6_600, &reply[1..]);
        arm.run_until(8_000);
        arm.board_received(basic, &mut heard);
        assert_eq!(heard, reply);
    }

    #[test]
    fn packets_that_arrive_together_wait_for_each_others_answers() {
        let mut arm = EmulatedArm::new(1, 2048);
        arm.set_tracing(true);
        let atom = arm.attach_board(0);
        arm.run_until(100);
        // Two READs of the present position (servos 1 and 2) in one chunk: the emulated Atom
        // timed the first out while its bytes waited in the socket.
        let read_1 = [0xFF, 0xFF, 0x01, 0x04, 0x02, 0x38, 0x02, 0xBE];
        let read_2 = [0xFF, 0xFF, 0x02, 0x04, 0x02, 0x38, 0x02, 0xBD];
        arm.board_sent(atom, 100, &[read_1, read_2].concat());
        arm.run_until(5_000);
        let mut heard = Vec::new();
        arm.board_received(atom, &mut heard);
        let answer_1 = [0xFF, 0xFF, 0x01, 0x04, 0x00, 0x00, 0x08, 0xF2];
        let answer_2 = [0xFF, 0xFF, 0x02, 0x04, 0x00, 0x00, 0x08, 0xF1];
        assert_eq!(heard, [answer_1, answer_2].concat(), "{heard:02X?}");
        assert!(arm.take_trace().iter().all(|b| !b.garbled));
    }

    #[test]
    fn whole_frames_held_past_the_stale_time_still_go_one_at_a_time() {
        let mut gate = FrameGate::new();
        let read_1 = [0xFF, 0xFF, 0x01, 0x04, 0x02, 0x38, 0x02, 0xBE];
        let read_2 = [0xFF, 0xFF, 0x02, 0x04, 0x02, 0x38, 0x02, 0xBD];
        gate.push(0, &[read_1, read_2].concat());
        assert_eq!(released(&mut gate, 10 * STALE_AFTER_NS), read_1);
        assert_eq!(released(&mut gate, 10 * STALE_AFTER_NS), read_2);
        assert!(!gate.holds());
    }
}

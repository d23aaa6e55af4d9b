//! Where the time of one host round trip through the Basic goes, hop by hop, from a trace of
//! every byte on the Basic's USB serial (both ways) and on the bus, and of the moments the
//! Basic took a host frame ([`VirtualRobot::set_hop_tracing`](super::VirtualRobot::set_hop_tracing)).
//!
//! A round trip is cut at its milestones ([`Hops`]): the request on the USB wire, the Basic's
//! decision, its first byte on the bus, the Atom's reply on the bus, the reply on the USB wire.
//! Each hop is the time between two milestones on the critical path, so the hops add up to the
//! round trip whatever overlaps: a Basic that starts the USB write before the Atom's reply has
//! ended on the bus (cut-through) shows the reply's bus time only up to that start.

use protocol_core::{Frame, FrameDecoder};

use super::wire::{BusByte, LineByte, StationId};

/// Something the Basic's firmware did, seen from outside between two of its polls.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BasicMark {
    /// It took a host frame in framed mode (its count of host frames grew): the poll that
    /// decided what to do with the request.
    HostFrame,
    /// It passed a reply from the Atom to the client that asked.
    ReplyForwarded,
}

/// Every byte of a traced stretch of time, and the Basic's marks, in time order.
#[derive(Clone, Debug, Default)]
pub struct HopTrace {
    /// Every byte on the bus.
    pub bus: Vec<BusByte>,
    /// Every byte from the host to the Basic (its USB serial's receive line).
    pub to_basic: Vec<LineByte>,
    /// Every byte from the Basic to the host.
    pub to_host: Vec<LineByte>,
    /// The Basic's marks, with the virtual time of the poll that made them (ns).
    pub basic_marks: Vec<(u64, BasicMark)>,
}

impl HopTrace {
    /// Appends `other` (traced after `self`).
    pub fn extend(&mut self, other: HopTrace) {
        self.bus.extend(other.bus);
        self.to_basic.extend(other.to_basic);
        self.to_host.extend(other.to_host);
        self.basic_marks.extend(other.basic_marks);
    }

    /// The round trips of the requests with command `cmd` the host sent on the Basic's USB
    /// serial, in order, each with its milestones; a request whose reply never reached the
    /// host (or whose path cannot be followed) is left out. Requests are matched to what
    /// follows them: the next copy the Basic put on the bus, the Atom's next frame with that
    /// command, the next such frame to the host.
    pub fn round_trips(&self, basic: StationId, atom: StationId, cmd: u8) -> Vec<Hops> {
        let requests = line_frames(&self.to_basic, cmd);
        let replies = line_frames(&self.to_host, cmd);
        let forwarded = bus_frames(&self.bus, basic, cmd);
        let answers = bus_frames(&self.bus, atom, cmd);
        let mut out = Vec::new();
        for (i, request) in requests.iter().enumerate() {
            let next_request_ns = requests.get(i + 1).map_or(u64::MAX, |r| r.first_start_ns);
            let in_ns = request.last_end_ns;
            let Some(reply) = replies
                .iter()
                .find(|r| r.first_start_ns >= in_ns && r.first_start_ns < next_request_ns)
            else {
                continue;
            };
            let Some(decided_ns) = self
                .basic_marks
                .iter()
                .find(|(t, m)| *t >= in_ns && *m == BasicMark::HostFrame)
                .map(|(t, _)| *t)
            else {
                continue;
            };
            // The Atom's answer: its first frame with the command after the request reached
            // the bus, and before the reply reached the host.
            let Some(answer) = answers
                .iter()
                .find(|a| a.first_start_ns >= in_ns && a.first_start_ns <= reply.first_start_ns)
            else {
                continue;
            };
            // The copies the Basic sent (more than one after a collision): the first, and
            // the last one before the answer.
            let copies: Vec<&Span> = forwarded
                .iter()
                .filter(|f| f.first_start_ns >= in_ns && f.last_end_ns <= answer.first_start_ns)
                .collect();
            let (Some(first), Some(last)) = (copies.first(), copies.last()) else {
                continue;
            };
            out.push(Hops {
                request_start_ns: request.first_start_ns,
                request_in_ns: in_ns,
                decided_ns,
                bus_start_ns: first.first_start_ns,
                bus_end_ns: last.last_end_ns,
                bus_copies: copies.len(),
                answer_start_ns: answer.first_start_ns,
                answer_end_ns: answer.last_end_ns,
                usb_start_ns: reply.first_start_ns,
                usb_end_ns: reply.last_end_ns,
            });
        }
        out
    }
}

/// The milestones of one round trip, in virtual ns.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Hops {
    /// The request's first byte starts on the USB wire (the host wrote it).
    pub request_start_ns: u64,
    /// Its last byte has arrived at the Basic.
    pub request_in_ns: u64,
    /// The Basic's poll that took the frame.
    pub decided_ns: u64,
    /// The Basic's first byte of it starts on the bus.
    pub bus_start_ns: u64,
    /// The last byte of the copy the Atom answered ends on the bus.
    pub bus_end_ns: u64,
    /// How many copies the Basic sent (1 unless a collision made it send again).
    pub bus_copies: usize,
    /// The Atom's reply starts on the bus.
    pub answer_start_ns: u64,
    /// The Atom's reply ends on the bus.
    pub answer_end_ns: u64,
    /// The reply's first byte starts on the USB wire to the host.
    pub usb_start_ns: u64,
    /// Its last byte has arrived at the host.
    pub usb_end_ns: u64,
}

/// The names of the hops [`Hops::hops_ns`] gives, in order.
pub const HOP_NAMES: [&str; 8] = [
    "host -> Basic, USB wire",
    "Basic: request in -> decision",
    "Basic: decision -> first byte on the bus (bus gap)",
    "bus wire, request",
    "Atom: request in -> reply starts",
    "bus wire, reply (until the USB write starts)",
    "Basic: reply in -> USB write starts",
    "Basic -> host, USB wire",
];

impl Hops {
    /// The hops on the critical path, in ns, in the order of [`HOP_NAMES`]; they add up to
    /// [`Hops::round_trip_ns`].
    pub fn hops_ns(&self) -> [u64; 8] {
        let reply_seen_ns = self.answer_end_ns.min(self.usb_start_ns);
        [
            self.request_in_ns - self.request_start_ns,
            self.decided_ns - self.request_in_ns,
            self.bus_start_ns.saturating_sub(self.decided_ns),
            self.bus_end_ns.saturating_sub(self.bus_start_ns),
            self.answer_start_ns.saturating_sub(self.bus_end_ns),
            reply_seen_ns.saturating_sub(self.answer_start_ns),
            self.usb_start_ns.saturating_sub(reply_seen_ns),
            self.usb_end_ns - self.usb_start_ns,
        ]
    }

    /// From the request's first byte on the USB wire to the reply's last byte at the host.
    pub fn round_trip_ns(&self) -> u64 {
        self.usb_end_ns - self.request_start_ns
    }
}

/// Where one frame lies in time.
#[derive(Clone, Copy, Debug)]
struct Span {
    first_start_ns: u64,
    last_end_ns: u64,
}

/// The frames with command `cmd` among `bytes` (each with its start and end times).
fn frames_in(bytes: &[(u8, u64, u64)], cmd: u8) -> Vec<Span> {
    let mut decoder = FrameDecoder::new();
    let mut out = Vec::new();
    for (i, &(byte, _, end_ns)) in bytes.iter().enumerate() {
        let mut found = decoder.push(byte);
        while let Some(frame) = found {
            let first = (i + 1).saturating_sub(frame.encoded_len());
            if frame.cmd() == cmd
                && let Some(&(_, first_start_ns, _)) = bytes.get(first)
            {
                out.push(Span {
                    first_start_ns,
                    last_end_ns: end_ns,
                });
            }
            found = decoder.next_frame();
        }
    }
    out
}

fn line_frames(line: &[LineByte], cmd: u8) -> Vec<Span> {
    let bytes: Vec<(u8, u64, u64)> = line
        .iter()
        .map(|b| (b.byte, b.start_ns, b.end_ns))
        .collect();
    frames_in(&bytes, cmd)
}

fn bus_frames(bus: &[BusByte], from: StationId, cmd: u8) -> Vec<Span> {
    let bytes: Vec<(u8, u64, u64)> = bus
        .iter()
        .filter(|b| b.from == from)
        .map(|b| (b.byte, b.start_ns, b.end_ns))
        .collect();
    frames_in(&bytes, cmd)
}

/// The frame whose bytes `line` carried, if it holds exactly one (for tests and tools).
pub fn only_frame(line: &[LineByte]) -> Option<Frame> {
    let mut frames = Vec::new();
    let bytes: Vec<u8> = line.iter().map(|b| b.byte).collect();
    FrameDecoder::new().feed(&bytes, |f| frames.push(f));
    (frames.len() == 1).then(|| frames.remove(0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::{RobotConfig, VirtualRobot};
    use protocol_core::command::{Request, cmd};
    use protocol_core::timing::{BUS_BAUD, HOST_BAUD, wire_time_ns};

    #[test]
    fn the_hops_of_a_get_angles_add_up_and_each_wire_hop_is_its_wire_time() {
        let mut robot = VirtualRobot::new(RobotConfig::default());
        robot.run_for(1_500_000);
        robot.set_hop_tracing(true);
        let request = Request::GetAngles.to_frame();
        let reply = robot.transact(&request).expect("answered");
        robot.run_for(5_000);
        let trace = robot.take_hop_trace();
        let basic = robot.basic_station().expect("a Basic");
        let trips = trace.round_trips(basic, robot.atom_station(), cmd::GET_ANGLES);
        assert_eq!(trips.len(), 1, "{trips:?}");
        let hops = trips[0];
        assert_eq!(hops.hops_ns().iter().sum::<u64>(), hops.round_trip_ns());
        let [usb_in, _, _, bus_out, _, _, _, usb_out] = hops.hops_ns();
        assert_eq!(usb_in, 5 * wire_time_ns(1, HOST_BAUD), "5 bytes at 115200");
        assert_eq!(bus_out, wire_time_ns(5, BUS_BAUD));
        let reply_len = reply.encoded_len() as u32;
        assert_eq!(usb_out, u64::from(reply_len) * wire_time_ns(1, HOST_BAUD));
        assert_eq!(hops.bus_copies, 1);
        assert_eq!(
            only_frame(&trace.to_host).map(|f| f.cmd()),
            Some(cmd::GET_ANGLES)
        );
    }
}

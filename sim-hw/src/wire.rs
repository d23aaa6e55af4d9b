//! Simulated wires with byte timing: the shared half-duplex bus and point-to-point serial lines.
//!
//! * [`Bus`]: one wire every station hears (Basic, Atom, servos, a noise source). A station
//!   queues bytes; its transmitter sends them one per byte time (8N1, 10 bits), back to back.
//!   Every other station receives each byte when its stop bit ends; the sender hears its own
//!   byte only if it [hears its echo](Bus::attach). Two transmissions that overlap in time
//!   corrupt each other: every listener gets both bytes garbled.
//! * [`SerialLine`]: one direction of a UART link (the 115200 USB serial of a board). A host
//!   link is two of them.
//!
//! Time is in nanoseconds here (a byte at 115200 baud is 86 806 ns), always passed in. The
//! caller advances a wire only to instants at which it also polls the stations, and must stop
//! at every [`Bus::next_event_ns`] so that back-to-back bytes start exactly when the previous
//! byte ends.

use std::collections::VecDeque;

use protocol_core::BytePort;
use protocol_core::timing::{BUS_BAUD, wire_time_ns};

/// Most bytes a station's receive buffer holds; further bytes are lost (a UART overrun), as on
/// a board whose firmware stops reading. 4 KiB is far more than any UART ring buffer in use.
pub const RX_BUFFER_BYTES: usize = 4096;

/// Bytes a UART's receive FIFO holds (the ESP32's and the ESP32-C3's): while a board stands
/// still (a flash erase or write runs with interrupts off), what arrives beyond these is lost.
pub const UART_FIFO_BYTES: usize = 128;

/// A receiver whose board stands still: until `until_ns` it keeps at most `cap` bytes.
#[derive(Clone, Copy, Debug)]
struct Frozen {
    until_ns: u64,
    cap: usize,
}

impl Frozen {
    /// A receiver holding `held` bytes now, frozen until `until_ns`: only its FIFO takes more.
    fn new(held: usize, until_ns: u64) -> Self {
        Self {
            until_ns,
            cap: held + UART_FIFO_BYTES,
        }
    }

    /// How many bytes the receiver keeps for a byte arriving at `at_ns`.
    fn cap_at(frozen: Option<Self>, at_ns: u64) -> usize {
        match frozen {
            Some(f) if at_ns < f.until_ns => f.cap.min(RX_BUFFER_BYTES),
            _ => RX_BUFFER_BYTES,
        }
    }
}

/// A station on the [`Bus`], as returned by [`Bus::attach`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct StationId(usize);

impl StationId {
    /// The station's index in attach order (0 for the first station attached).
    pub fn index(self) -> usize {
        self.0
    }
}

/// One byte as it travelled on the bus, for latency measurements and debugging.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BusByte {
    /// Who sent it.
    pub from: StationId,
    /// The byte the sender meant to send.
    pub byte: u8,
    /// When its start bit began, in ns.
    pub start_ns: u64,
    /// When its stop bit ended (when listeners receive it), in ns.
    pub end_ns: u64,
    /// True if another transmission overlapped it, so every listener got garbage.
    pub garbled: bool,
}

/// One byte as it travelled on a [`SerialLine`], for latency measurements.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LineByte {
    /// The byte.
    pub byte: u8,
    /// When its start bit began, in ns.
    pub start_ns: u64,
    /// When its stop bit ended (when the receiving end has it), in ns.
    pub end_ns: u64,
}

/// A byte as a listener received it (garbled if it collided), with its sender.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct HeardByte {
    /// Who sent it.
    pub from: StationId,
    /// What listeners received.
    pub byte: u8,
    /// When it arrived (its stop bit ended), in ns.
    pub end_ns: u64,
}

#[derive(Clone, Debug, Default)]
struct Station {
    hears_echo: bool,
    /// False for a station that only transmits and reads the bus through the tap.
    receives: bool,
    tx: VecDeque<u8>,
    rx: VecDeque<u8>,
    /// End of the byte this station is sending now, if any.
    sending_until_ns: Option<u64>,
    overruns: u64,
    /// While its board stands still: only the UART's FIFO takes bytes.
    frozen: Option<Frozen>,
}

/// The shared half-duplex bus. See the [module doc](self).
#[derive(Clone, Debug)]
pub struct Bus {
    byte_time_ns: u64,
    stations: Vec<Station>,
    in_flight: Vec<BusByte>,
    rng: u64,
    trace: Option<Vec<BusByte>>,
    tap: Option<Vec<HeardByte>>,
    collisions: u64,
    last_end_ns: u64,
}

impl Bus {
    /// An empty bus at `baud` (8N1). `seed` makes the garbage of collisions reproducible.
    pub fn new(baud: u32, seed: u64) -> Self {
        Self {
            byte_time_ns: wire_time_ns(1, baud),
            stations: Vec::new(),
            in_flight: Vec::new(),
            // xorshift must not start at zero.
            rng: seed | 1,
            trace: None,
            tap: None,
            collisions: 0,
            last_end_ns: 0,
        }
    }

    /// The 1 Mbaud bus of the myCobot 280.
    pub fn mycobot(seed: u64) -> Self {
        Self::new(BUS_BAUD, seed)
    }

    /// Station `id`'s board stands still until `until_ns` (a flash erase or write): its UART
    /// keeps receiving into its FIFO only, bytes beyond [`UART_FIFO_BYTES`] are lost
    /// ([`Bus::overruns`]), and what it wrote goes out only then (its loop wrote it after the
    /// flash work, as far as the wire can tell).
    pub fn freeze_station(&mut self, id: StationId, until_ns: u64) {
        if let Some(station) = self.stations.get_mut(id.0) {
            station.frozen = Some(Frozen::new(station.rx.len(), until_ns));
        }
    }

    /// Duration of one byte on this bus, in ns.
    pub fn byte_time_ns(&self) -> u64 {
        self.byte_time_ns
    }

    /// Connects a station; `hears_echo` says whether it receives its own transmissions (TX and
    /// RX tied on its board).
    pub fn attach(&mut self, hears_echo: bool) -> StationId {
        self.stations.push(Station {
            hears_echo,
            receives: true,
            ..Station::default()
        });
        StationId(self.stations.len() - 1)
    }

    /// Connects a station whose receiver is not modelled per station: it transmits through its
    /// port, and what it hears is read once for all such stations from the [tap](Bus::take_heard)
    /// (the simulated servos share one packet decoder this way).
    pub fn attach_transmitter(&mut self) -> StationId {
        self.stations.push(Station::default());
        StationId(self.stations.len() - 1)
    }

    /// Empties a station's receive buffer and transmit queue, as a board reset does to its
    /// UART; a byte already on the wire still finishes.
    pub fn reset_station(&mut self, id: StationId) {
        if let Some(station) = self.stations.get_mut(id.0) {
            station.rx.clear();
            station.tx.clear();
        }
    }

    /// Starts (or stops) keeping every delivered byte, with its sender, for
    /// [`Bus::take_heard`]. Off by default.
    pub fn set_tap(&mut self, on: bool) {
        self.tap = if on { Some(Vec::new()) } else { None };
    }

    /// Moves the bytes delivered since the last call into `out` (nothing unless the tap is on).
    pub fn take_heard(&mut self, out: &mut Vec<HeardByte>) {
        if let Some(tap) = self.tap.as_mut() {
            out.append(tap);
        }
    }

    /// The station's byte port (read what it received, queue what it sends).
    pub fn port(&mut self, id: StationId) -> Option<BusPort<'_>> {
        self.stations
            .get_mut(id.0)
            .map(|station| BusPort { station })
    }

    /// Starts recording every byte ([`Bus::take_trace`]); off by default.
    pub fn set_tracing(&mut self, on: bool) {
        self.trace = if on { Some(Vec::new()) } else { None };
    }

    /// Bytes that completed since the last call (empty unless tracing is on), in end order.
    pub fn take_trace(&mut self) -> Vec<BusByte> {
        self.trace.as_mut().map(std::mem::take).unwrap_or_default()
    }

    /// Number of bytes that were garbled by an overlapping transmission so far.
    pub fn collisions(&self) -> u64 {
        self.collisions
    }

    /// Bytes a station lost because its receive buffer was full.
    pub fn overruns(&self, id: StationId) -> u64 {
        self.stations.get(id.0).map_or(0, |s| s.overruns)
    }

    /// True while any byte is on the wire or queued by any station.
    pub fn busy(&self) -> bool {
        !self.in_flight.is_empty() || self.stations.iter().any(|s| !s.tx.is_empty())
    }

    /// When the last byte on the wire ended, in ns (0 if none yet).
    pub fn last_activity_ns(&self) -> u64 {
        self.last_end_ns
    }

    /// The next instant the bus needs attention: the end of a byte on the wire.
    pub fn next_event_ns(&self) -> Option<u64> {
        let mut next = None;
        let frozen_senders = self
            .stations
            .iter()
            .filter(|s| !s.tx.is_empty())
            .filter_map(|s| s.frozen.map(|f| f.until_ns));
        for t in self
            .in_flight
            .iter()
            .map(|b| b.end_ns)
            .chain(frozen_senders)
        {
            if next.is_none_or(|n| t < n) {
                next = Some(t);
            }
        }
        next
    }

    /// Delivers every byte that has ended by `now_ns` to its listeners, in end order.
    pub fn deliver(&mut self, now_ns: u64) {
        while let Some(i) = self.first_ended(now_ns) {
            let b = self.in_flight.swap_remove(i);
            let heard = if b.garbled {
                b.byte ^ self.garble_mask()
            } else {
                b.byte
            };
            for (index, station) in self.stations.iter_mut().enumerate() {
                if index == b.from.0 {
                    station.sending_until_ns = None;
                    if !station.hears_echo {
                        continue;
                    }
                }
                if !station.receives {
                    continue;
                }
                if station.rx.len() < Frozen::cap_at(station.frozen, b.end_ns) {
                    station.rx.push_back(heard);
                } else {
                    station.overruns += 1;
                }
            }
            self.last_end_ns = self.last_end_ns.max(b.end_ns);
            if let Some(tap) = self.tap.as_mut() {
                tap.push(HeardByte {
                    from: b.from,
                    byte: heard,
                    end_ns: b.end_ns,
                });
            }
            if let Some(trace) = self.trace.as_mut() {
                trace.push(b);
            }
        }
    }

    /// Index of the in-flight byte that ended first, if any ended by `now_ns`.
    fn first_ended(&self, now_ns: u64) -> Option<usize> {
        let mut first: Option<(usize, u64)> = None;
        for (i, b) in self.in_flight.iter().enumerate() {
            if b.end_ns <= now_ns && first.is_none_or(|(_, end)| b.end_ns < end) {
                first = Some((i, b.end_ns));
            }
        }
        first.map(|(i, _)| i)
    }

    /// Starts the next queued byte of every station whose transmitter is free at `now_ns`.
    /// A byte that overlaps another one on the wire garbles both.
    pub fn start_transmissions(&mut self, now_ns: u64) {
        for index in 0..self.stations.len() {
            let Some(station) = self.stations.get_mut(index) else {
                continue;
            };
            if station.frozen.is_some_and(|f| now_ns >= f.until_ns) {
                station.frozen = None;
            }
            if station.sending_until_ns.is_some() || station.frozen.is_some() {
                continue;
            }
            let Some(byte) = station.tx.pop_front() else {
                continue;
            };
            let end_ns = now_ns + self.byte_time_ns;
            station.sending_until_ns = Some(end_ns);
            let mut garbled = false;
            for other in &mut self.in_flight {
                // Everything still in flight ends after now, so it overlaps the new byte.
                if !other.garbled {
                    self.collisions += 1;
                }
                other.garbled = true;
                garbled = true;
            }
            if garbled {
                self.collisions += 1;
            }
            self.in_flight.push(BusByte {
                from: StationId(index),
                byte,
                start_ns: now_ns,
                end_ns,
                garbled,
            });
        }
    }

    /// A nonzero xorshift mask: what a listener makes of two overlapping bytes.
    fn garble_mask(&mut self) -> u8 {
        loop {
            let mut x = self.rng;
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            self.rng = x;
            let mask = (x >> 24) as u8;
            if mask != 0 {
                return mask;
            }
        }
    }
}

/// A station's side of the [`Bus`] as a [`BytePort`].
#[derive(Debug)]
pub struct BusPort<'a> {
    station: &'a mut Station,
}

impl BusPort<'_> {
    /// Number of received bytes not read yet.
    pub fn rx_pending(&self) -> usize {
        self.station.rx.len()
    }
}

impl BytePort for BusPort<'_> {
    fn read_byte(&mut self) -> Option<u8> {
        self.station.rx.pop_front()
    }

    fn write(&mut self, bytes: &[u8]) {
        self.station.tx.extend(bytes.iter().copied());
    }

    fn tx_idle(&self) -> bool {
        self.station.tx.is_empty() && self.station.sending_until_ns.is_none()
    }
}

/// One direction of a UART link: bytes written at one end arrive at the other after their
/// wire time, one per byte time, back to back.
#[derive(Clone, Debug)]
pub struct SerialLine {
    byte_time_ns: u64,
    queued: VecDeque<u8>,
    /// When the byte now on the line (the front of `queued`) started.
    current_start_ns: u64,
    arrived: VecDeque<u8>,
    overruns: u64,
    /// While the receiving board stands still: only its UART's FIFO takes bytes.
    frozen: Option<Frozen>,
    /// Every byte that crossed the line, while tracing is on.
    trace: Option<Vec<LineByte>>,
}

impl SerialLine {
    /// An idle line at `baud` (8N1).
    pub fn new(baud: u32) -> Self {
        Self {
            byte_time_ns: wire_time_ns(1, baud),
            queued: VecDeque::new(),
            current_start_ns: 0,
            arrived: VecDeque::new(),
            overruns: 0,
            frozen: None,
            trace: None,
        }
    }

    /// Starts (or stops) recording every byte that crosses the line
    /// ([`SerialLine::take_trace`]); off by default.
    pub fn set_tracing(&mut self, on: bool) {
        self.trace = if on { Some(Vec::new()) } else { None };
    }

    /// Bytes that crossed the line since the last call (empty unless tracing is on), in order.
    pub fn take_trace(&mut self) -> Vec<LineByte> {
        self.trace.as_mut().map(std::mem::take).unwrap_or_default()
    }

    /// Queues `bytes` at `now_ns`; the first starts at once if the line is idle.
    pub fn send(&mut self, now_ns: u64, bytes: &[u8]) {
        if self.queued.is_empty() {
            self.current_start_ns = now_ns;
        }
        self.queued.extend(bytes.iter().copied());
    }

    /// Moves every byte whose stop bit ended by `now_ns` to the receiving end.
    pub fn deliver(&mut self, now_ns: u64) {
        while self.current_start_ns + self.byte_time_ns <= now_ns {
            let Some(byte) = self.queued.pop_front() else {
                break;
            };
            if let Some(trace) = self.trace.as_mut() {
                trace.push(LineByte {
                    byte,
                    start_ns: self.current_start_ns,
                    end_ns: self.current_start_ns + self.byte_time_ns,
                });
            }
            self.current_start_ns += self.byte_time_ns;
            if self.arrived.len() < Frozen::cap_at(self.frozen, self.current_start_ns) {
                self.arrived.push_back(byte);
            } else {
                self.overruns += 1;
            }
        }
        if self.frozen.is_some_and(|f| now_ns >= f.until_ns) {
            self.frozen = None;
        }
    }

    /// The receiving board stands still until `until_ns`, like [`Bus::freeze_station`].
    pub fn freeze_receiver(&mut self, until_ns: u64) {
        self.frozen = Some(Frozen::new(self.arrived.len(), until_ns));
    }

    /// The sending board stands still until `until_ns`: what it queued starts only then.
    pub fn hold_sending_until(&mut self, until_ns: u64) {
        if !self.queued.is_empty() {
            self.current_start_ns = self.current_start_ns.max(until_ns);
        }
    }

    /// When the byte on the line arrives, if one is on the line.
    pub fn next_event_ns(&self) -> Option<u64> {
        (!self.queued.is_empty()).then_some(self.current_start_ns + self.byte_time_ns)
    }

    /// Takes the next byte that has arrived.
    pub fn receive(&mut self) -> Option<u8> {
        self.arrived.pop_front()
    }

    /// Takes every byte that has arrived, appending them to `out`.
    pub fn receive_all(&mut self, out: &mut Vec<u8>) {
        out.extend(self.arrived.drain(..));
    }

    /// True when nothing is queued or on the line.
    pub fn idle(&self) -> bool {
        self.queued.is_empty()
    }

    /// Bytes lost because the receiver did not read them in time.
    pub fn overruns(&self) -> u64 {
        self.overruns
    }
}

/// A board's end of a full-duplex serial link as a [`BytePort`]: reads from one line, writes to
/// the other, stamping writes with the time of the current poll.
#[derive(Debug)]
pub struct SerialPort<'a> {
    /// Line the board receives on.
    pub rx: &'a mut SerialLine,
    /// Line the board transmits on.
    pub tx: &'a mut SerialLine,
    /// Time of the poll this port is lent to, in ns.
    pub now_ns: u64,
}

impl BytePort for SerialPort<'_> {
    fn read_byte(&mut self) -> Option<u8> {
        self.rx.receive()
    }

    fn write(&mut self, bytes: &[u8]) {
        self.tx.send(self.now_ns, bytes);
    }

    fn tx_idle(&self) -> bool {
        self.tx.idle()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use protocol_core::timing::HOST_BAUD;

    /// Runs the bus from `from_ns` to `to_ns`, stopping at every byte end.
    fn run(bus: &mut Bus, from_ns: u64, to_ns: u64) {
        let mut now = from_ns;
        bus.start_transmissions(now);
        while let Some(next) = bus.next_event_ns().filter(|&t| t <= to_ns) {
            now = next;
            bus.deliver(now);
            bus.start_transmissions(now);
        }
        bus.deliver(to_ns.max(now));
    }

    fn read_all(bus: &mut Bus, id: StationId) -> Vec<u8> {
        let mut port = bus.port(id).unwrap();
        std::iter::from_fn(|| port.read_byte()).collect()
    }

    #[test]
    fn a_frozen_board_keeps_only_a_fifo_of_bytes_and_sends_when_it_goes_on() {
        let mut bus = Bus::mycobot(1);
        let sender = bus.attach(false);
        let frozen = bus.attach(false);
        bus.port(frozen).unwrap().write(&[0xAA]);
        bus.freeze_station(frozen, 3_000_000);
        bus.port(sender).unwrap().write(&[7; 200]);
        run(&mut bus, 0, 2_999_999);
        assert_eq!(read_all(&mut bus, frozen).len(), UART_FIFO_BYTES);
        assert_eq!(bus.overruns(frozen), 200 - UART_FIFO_BYTES as u64);
        assert!(
            read_all(&mut bus, sender).is_empty(),
            "nothing sent while frozen"
        );
        run(&mut bus, 2_999_999, 3_020_000);
        assert_eq!(read_all(&mut bus, sender), [0xAA], "sent once it goes on");
        // Unfrozen, the whole buffer takes bytes again.
        bus.port(sender).unwrap().write(&[7; 200]);
        run(&mut bus, 3_020_000, 6_000_000);
        assert_eq!(read_all(&mut bus, frozen).len(), 200);
    }

    #[test]
    fn a_frozen_serial_receiver_keeps_only_a_fifo_of_bytes() {
        let mut line = SerialLine::new(HOST_BAUD);
        line.freeze_receiver(100_000_000);
        line.send(0, &[1; 300]);
        line.deliver(100_000_000);
        let mut got = Vec::new();
        line.receive_all(&mut got);
        assert_eq!(got.len(), UART_FIFO_BYTES);
        assert_eq!(line.overruns(), 300 - UART_FIFO_BYTES as u64);
    }

    #[test]
    fn bytes_arrive_one_per_byte_time_at_every_listener() {
        let mut bus = Bus::mycobot(1);
        let a = bus.attach(false);
        let b = bus.attach(false);
        let c = bus.attach(false);
        bus.port(a).unwrap().write(&[1, 2, 3]);
        run(&mut bus, 0, 29_999);
        assert_eq!(read_all(&mut bus, b), vec![1, 2]);
        run(&mut bus, 29_999, 30_000);
        assert_eq!(read_all(&mut bus, b), vec![3]);
        assert_eq!(read_all(&mut bus, c), vec![1, 2, 3]);
        assert!(read_all(&mut bus, a).is_empty(), "no echo configured");
        assert!(bus.port(a).unwrap().tx_idle());
        assert_eq!(bus.collisions(), 0);
    }

    #[test]
    fn echo_is_heard_only_by_stations_wired_for_it() {
        let mut bus = Bus::mycobot(1);
        let echo = bus.attach(true);
        let quiet = bus.attach(false);
        bus.port(echo).unwrap().write(&[0xAA]);
        run(&mut bus, 0, 10_000);
        assert_eq!(read_all(&mut bus, echo), vec![0xAA]);
        assert_eq!(read_all(&mut bus, quiet), vec![0xAA]);
    }

    #[test]
    fn transmitter_is_busy_until_the_last_stop_bit() {
        let mut bus = Bus::mycobot(1);
        let a = bus.attach(false);
        bus.port(a).unwrap().write(&[1, 2]);
        run(&mut bus, 0, 15_000);
        assert!(!bus.port(a).unwrap().tx_idle());
        run(&mut bus, 15_000, 20_000);
        assert!(bus.port(a).unwrap().tx_idle());
    }

    #[test]
    fn overlapping_transmissions_garble_both_bytes_for_everyone() {
        let mut bus = Bus::mycobot(7);
        let a = bus.attach(true);
        let b = bus.attach(true);
        let listener = bus.attach(false);
        bus.port(a).unwrap().write(&[0x11]);
        bus.start_transmissions(0);
        bus.port(b).unwrap().write(&[0x22]);
        // b starts half a byte later: both bytes overlap.
        bus.start_transmissions(5_000);
        run(&mut bus, 5_000, 20_000);
        let heard = read_all(&mut bus, listener);
        assert_eq!(heard.len(), 2);
        assert_ne!(heard[0], 0x11);
        assert_ne!(heard[1], 0x22);
        let a_echo = read_all(&mut bus, a);
        assert_ne!(a_echo[0], 0x11, "the sender sees its echo differ");
        assert_eq!(bus.collisions(), 2);
        // The wire recovers: the next byte alone is clean.
        bus.port(a).unwrap().write(&[0x33]);
        run(&mut bus, 20_000, 30_000);
        assert_eq!(read_all(&mut bus, listener), vec![0x33]);
    }

    #[test]
    fn trace_records_senders_and_times() {
        let mut bus = Bus::mycobot(1);
        let a = bus.attach(false);
        bus.set_tracing(true);
        bus.port(a).unwrap().write(&[9, 8]);
        run(&mut bus, 100, 20_100);
        let trace = bus.take_trace();
        assert_eq!(trace.len(), 2);
        assert_eq!(
            (trace[0].byte, trace[0].start_ns, trace[0].end_ns),
            (9, 100, 10_100)
        );
        assert_eq!((trace[1].byte, trace[1].start_ns), (8, 10_100));
        assert!(trace.iter().all(|b| b.from == a && !b.garbled));
    }

    #[test]
    fn the_tap_hears_everything_with_its_sender_and_transmitters_receive_nothing() {
        let mut bus = Bus::mycobot(1);
        let a = bus.attach(false);
        let t = bus.attach_transmitter();
        bus.set_tap(true);
        bus.port(a).unwrap().write(&[1]);
        run(&mut bus, 0, 10_000);
        bus.port(t).unwrap().write(&[2]);
        run(&mut bus, 10_000, 20_000);
        let mut heard = Vec::new();
        bus.take_heard(&mut heard);
        let got: Vec<(StationId, u8, u64)> =
            heard.iter().map(|h| (h.from, h.byte, h.end_ns)).collect();
        assert_eq!(got, vec![(a, 1, 10_000), (t, 2, 20_000)]);
        assert_eq!(bus.port(t).unwrap().rx_pending(), 0);
        assert_eq!(read_all(&mut bus, a), vec![2]);
    }

    #[test]
    fn full_receive_buffer_overruns_instead_of_growing() {
        let mut bus = Bus::mycobot(1);
        let a = bus.attach(false);
        let b = bus.attach(false);
        bus.port(a).unwrap().write(&vec![0x55; RX_BUFFER_BYTES + 3]);
        run(&mut bus, 0, 10_000 * (RX_BUFFER_BYTES as u64 + 3));
        assert_eq!(bus.port(b).unwrap().rx_pending(), RX_BUFFER_BYTES);
        assert_eq!(bus.overruns(b), 3);
    }

    #[test]
    fn serial_line_trace_has_each_bytes_wire_time() {
        let mut line = SerialLine::new(HOST_BAUD);
        line.send(0, &[7]);
        line.deliver(1_000_000);
        assert!(line.take_trace().is_empty(), "off by default");
        line.set_tracing(true);
        line.send(1_000_000, &[1, 2]);
        line.deliver(2_000_000);
        let trace = line.take_trace();
        let times: Vec<(u8, u64, u64)> = trace
            .iter()
            .map(|b| (b.byte, b.start_ns, b.end_ns))
            .collect();
        assert_eq!(
            times,
            [(1, 1_000_000, 1_086_806), (2, 1_086_806, 1_173_612)]
        );
        assert!(line.take_trace().is_empty(), "taken");
    }

    #[test]
    fn serial_line_paces_bytes_at_115200() {
        let mut line = SerialLine::new(HOST_BAUD);
        line.send(1_000, &[1, 2, 3]);
        assert_eq!(line.next_event_ns(), Some(1_000 + 86_806));
        line.deliver(1_000 + 86_805);
        assert_eq!(line.receive(), None);
        line.deliver(1_000 + 2 * 86_806);
        let mut got = Vec::new();
        line.receive_all(&mut got);
        assert_eq!(got, vec![1, 2]);
        assert!(!line.idle());
        line.deliver(1_000_000);
        assert_eq!(line.receive(), Some(3));
        assert!(line.idle());
        // A later write starts when it is made, not back-dated to the last byte.
        line.send(2_000_000, &[4]);
        line.deliver(2_000_000 + 86_805);
        assert_eq!(line.receive(), None);
    }
}

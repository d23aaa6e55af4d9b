//! Property tests of the timed bus listener.
//!
//! * Any bytes, any timing (even backwards), any transmissions, any config: nothing panics,
//!   every received byte comes out exactly once or is dropped as own echo, and every frame or
//!   packet it gives out was in the bytes it gave out.
//! * Frames and packets that follow a quiet gap are found, whatever noise came before them.
//! * On a line that echoes, the station's own transmissions never come out (as bytes, frames or
//!   packets), whatever they contain, while other stations' frames and packets all do.
//! * On a line that does not echo, an answer read late (the station's loop stood still after
//!   its transmission) is always heard, even when it repeats the transmission byte for byte.
//!
//! Default case counts keep `cargo test` fast; raise them with `PROPTEST_CASES`.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)]

use proptest::prelude::*;

use protocol_core::Frame;

mod strategies;
use protocol_core::listener::{ECHO_CAPACITY, Echo, EchoMode, Heard, Listener, ListenerConfig};
use protocol_core::servo::Packet;
use protocol_core::timing::{BUS_FRAME_GAP_US, BUS_QUIET_BEFORE_SEND_US, ECHO_GRACE_US};
use strategies::{any_frame, any_packet};

/// One byte time at 1 Mbaud, in microseconds.
const BYTE_US: u64 = 10;

/// 256 cases, or `PROPTEST_CASES`. A failing case is printed, never written to a file: a
/// failure a run finds becomes a unit test beside the listener, and the next run searches anew.
fn proptest_config() -> ProptestConfig {
    let cases = std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|c| c.parse().ok())
        .unwrap_or(256);
    ProptestConfig {
        cases,
        failure_persistence: None,
        ..ProptestConfig::default()
    }
}

fn echo_mode() -> impl Strategy<Value = EchoMode> {
    prop_oneof![
        Just(EchoMode::Auto),
        Just(EchoMode::Present),
        Just(EchoMode::Absent)
    ]
}

fn config() -> impl Strategy<Value = ListenerConfig> {
    (
        any::<bool>(),
        any::<bool>(),
        0u64..3_000,
        0u64..300,
        echo_mode(),
    )
        .prop_map(|(frames, packets, frame_gap, packet_gap, echo)| {
            ListenerConfig::new()
                .with_frames(frames)
                .with_packets(packets)
                .with_bytes(true)
                .with_frame_gap_us(frame_gap)
                .with_packet_gap_us(packet_gap)
                .with_echo(echo)
        })
}

/// A byte rich in both headers, footers and small LENs, so frames, packets and near misses
/// occur. Picked from a table rather than by `prop_oneof!`, whose every choice reseeds a random
/// generator: the deep runs (a million cases) spend their time on the listener, not on that.
fn wire_byte() -> impl Strategy<Value = u8> {
    (0u8..12, any::<u8>()).prop_map(|(pick, any)| match pick {
        0 | 1 => 0xFE,
        2 | 3 => 0xFF,
        4 => 0xFA,
        5 => 0x02,
        6 => 0x04,
        _ => any,
    })
}

/// Up to `max` bytes rich in headers, footers and small LENs ([`wire_byte`]).
fn wire_bytes(max: usize) -> impl Strategy<Value = Vec<u8>> {
    prop::collection::vec(wire_byte(), 0..max)
}

/// A frame or a packet, with its wire bytes.
#[derive(Clone, Debug)]
enum Item {
    Frame(Frame),
    Packet(Packet),
}

impl Item {
    fn bytes(&self) -> Vec<u8> {
        match self {
            Item::Frame(f) => f.to_bytes().to_vec(),
            Item::Packet(p) => p.to_bytes().to_vec(),
        }
    }
}

fn any_item() -> impl Strategy<Value = Item> {
    prop_oneof![
        any_frame().prop_map(Item::Frame),
        any_packet().prop_map(Item::Packet)
    ]
}

/// A servo packet whose data holds a whole host frame (a servo's answer to a long read can).
fn packet_around_a_frame() -> impl Strategy<Value = Item> {
    (
        0u8..=0xFE,
        any::<u8>(),
        wire_bytes(12),
        prop::collection::vec(any::<u8>(), 0..=40)
            .prop_map(|data| Frame::new(0x20, &data).unwrap()),
        any::<u8>(),
        wire_bytes(12),
    )
        .prop_map(|(id, code, before, mut frame, cmd, after)| {
            frame = Frame::new(cmd, frame.data()).unwrap();
            let mut params = before;
            params.extend_from_slice(&frame.to_bytes());
            params.extend_from_slice(&after);
            Item::Packet(Packet::new(id, code, &params).unwrap())
        })
}

/// What a station does to its listener.
#[derive(Clone, Debug)]
enum Op {
    /// Time moves by the given microseconds (or jumps anywhere), then a byte arrives.
    Push(u64, u8),
    /// The station writes bytes.
    Transmit(u64, Vec<u8>),
    /// A poll.
    Tick(u64),
    /// The station drops what is in progress.
    DropPartials,
}

fn op() -> impl Strategy<Value = Op> {
    // A time step of up to 300 us, one time in nine anywhere; the op picked from a table (see
    // `wire_byte`): 6 pushes, 1 transmission, 2 polls, 1 drop in ten. A transmission's bytes
    // are drawn from a seed, so the other nine kinds cost no byte vector each.
    let dt = (0u8..9, 0u64..300, any::<u64>()).prop_map(
        |(pick, small, any)| {
            if pick == 0 { any } else { small }
        },
    );
    (0u8..10, dt, wire_byte(), 0..2 * ECHO_CAPACITY, any::<u64>()).prop_map(
        |(pick, dt, b, len, seed)| match pick {
            0..=5 => Op::Push(dt, b),
            6 => Op::Transmit(dt, seeded_wire_bytes(seed, len)),
            7 | 8 => Op::Tick(dt),
            _ => Op::DropPartials,
        },
    )
}

/// `len` bytes with [`wire_byte`]'s mix, drawn from `seed` (xorshift64).
fn seeded_wire_bytes(seed: u64, len: usize) -> Vec<u8> {
    let mut seed = seed | 1;
    (0..len)
        .map(|_| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            match seed % 12 {
                0 | 1 => 0xFE,
                2 | 3 => 0xFF,
                4 => 0xFA,
                5 => 0x02,
                6 => 0x04,
                _ => (seed >> 32) as u8,
            }
        })
        .collect()
}

/// What came out of a listener, sorted by kind.
#[derive(Default, Debug)]
struct Out {
    bytes: Vec<u8>,
    frames: Vec<Frame>,
    packets: Vec<Packet>,
    verdicts: Vec<Echo>,
}

impl Out {
    fn take(&mut self, heard: Heard) {
        match heard {
            Heard::Byte(b) => self.bytes.push(b),
            Heard::Frame(f) => self.frames.push(f),
            Heard::Packet(p) => self.packets.push(p),
            Heard::Echo(e) => self.verdicts.push(e),
        }
    }
}

fn contains(haystack: &[u8], needle: &[u8]) -> bool {
    haystack.windows(needle.len()).any(|w| w == needle)
}

/// True if `want` occurs in `got` in order (other items may come between).
fn in_order<T: PartialEq>(got: &[T], want: &[T]) -> bool {
    let mut got = got.iter();
    want.iter().all(|w| got.any(|g| g == w))
}

/// A timeline event: a transmission, a received byte or a poll, at a time.
#[derive(Clone, Debug)]
enum At {
    Transmit(Vec<u8>),
    Push(u8),
    Tick,
}

/// Runs a timeline, sorted by time; at equal times transmissions first, then bytes, then polls.
fn play(rx: &mut Listener, mut events: Vec<(u64, At)>) -> Out {
    events.sort_by_key(|(t, e)| {
        let rank = match e {
            At::Transmit(_) => 0,
            At::Push(_) => 1,
            At::Tick => 2,
        };
        (*t, rank)
    });
    let mut out = Out::default();
    for (t, e) in events {
        match e {
            At::Transmit(bytes) => rx.on_transmit(t, &bytes),
            At::Push(b) => rx.push(t, b, &mut |h| out.take(h)),
            At::Tick => rx.on_time(t, &mut |h| out.take(h)),
        }
    }
    out
}

proptest! {
    #![proptest_config(proptest_config())]

    #[test]
    fn any_bytes_any_timing_never_panic_and_every_byte_is_accounted_for(
        config in config(),
        ops in prop::collection::vec(op(), 0..300),
        start in prop_oneof![Just(0u64), any::<u64>()],
    ) {
        let mut rx = Listener::new(config);
        let mut out = Out::default();
        let mut pushed = Vec::new();
        let mut now = start;
        for op in ops {
            match op {
                Op::Push(dt, b) => {
                    now = now.wrapping_add(dt);
                    pushed.push(b);
                    rx.push(now, b, &mut |h| out.take(h));
                }
                Op::Transmit(dt, bytes) => {
                    now = now.wrapping_add(dt);
                    rx.on_transmit(now, &bytes);
                }
                Op::Tick(dt) => {
                    now = now.wrapping_add(dt);
                    rx.on_time(now, &mut |h| out.take(h));
                }
                Op::DropPartials => rx.drop_partials(),
            }
            let _ = (rx.quiet_us(now), rx.frame_in_progress(), rx.take_collision());
        }
        // The end of time closes any echo window: nothing is held any more.
        rx.on_time(u64::MAX, &mut |h| out.take(h));
        prop_assert!(!rx.echo_pending());
        prop_assert_eq!(out.bytes.len() + rx.echo_bytes() as usize, pushed.len());
        prop_assert!(in_order(&pushed, &out.bytes), "bytes came out reordered");
        for f in &out.frames {
            prop_assert!(contains(&out.bytes, &f.to_bytes()), "{:?} was not heard", f);
        }
        for p in &out.packets {
            prop_assert!(contains(&out.bytes, &p.to_bytes()), "{:?} was not heard", p);
        }
    }

    #[test]
    fn frames_and_packets_after_a_quiet_gap_are_found_whatever_came_before(
        items in prop::collection::vec((wire_bytes(80), any_item()), 1..6),
        tail in wire_bytes(80),
        polls in prop::collection::vec(0u64..10_000, 0..40),
    ) {
        let mut rx = Listener::default();
        let mut events = Vec::new();
        let mut t = 0;
        for (noise, item) in &items {
            for &b in noise {
                t += BYTE_US;
                events.push((t, At::Push(b)));
            }
            // A quiet gap the station notices (it polls during it).
            t += BUS_FRAME_GAP_US;
            events.push((t, At::Tick));
            t += BYTE_US;
            for b in item.bytes() {
                t += BYTE_US;
                events.push((t, At::Push(b)));
            }
        }
        for &b in &tail {
            t += BYTE_US;
            events.push((t, At::Push(b)));
        }
        events.extend(polls.into_iter().map(|p| (p, At::Tick)));
        let out = play(&mut rx, events);
        let want_frames: Vec<Frame> = items
            .iter()
            .filter_map(|(_, i)| match i { Item::Frame(f) => Some(f.clone()), _ => None })
            .collect();
        let want_packets: Vec<Packet> = items
            .iter()
            .filter_map(|(_, i)| match i { Item::Packet(p) => Some(p.clone()), _ => None })
            .collect();
        prop_assert!(in_order(&out.frames, &want_frames), "{:?} in {:?}", want_frames, out.frames);
        prop_assert!(in_order(&out.packets, &want_packets), "{:?} in {:?}", want_packets, out.packets);
    }

    #[test]
    fn own_echo_never_comes_out_on_a_line_that_echoes(
        script in prop::collection::vec(
            prop_oneof![
                // The station's own transmission: anything, even a frame or packet...
                prop_oneof![
                    any_item().prop_map(|i| i.bytes()),
                    prop::collection::vec(any::<u8>(), 1..ECHO_CAPACITY),
                ].prop_map(Ok),
                // ...or another station's frame or packet.
                any_item().prop_map(Err),
            ],
            0..12,
        ),
        latency_us in 0u64..ECHO_GRACE_US - BYTE_US,
        echo in prop_oneof![Just(EchoMode::Auto), Just(EchoMode::Present)],
        polls in prop::collection::vec(0u64..20_000, 0..60),
    ) {
        let mut rx = Listener::new(ListenerConfig::new().with_bytes(true).with_echo(echo));
        let mut events = Vec::new();
        let mut foreign = Vec::new();
        let mut own_bytes = 0;
        let mut t = 100;
        for entry in &script {
            match entry {
                Ok(own) => {
                    events.push((t, At::Transmit(own.clone())));
                    for (i, &b) in own.iter().enumerate() {
                        events.push((t + BYTE_US * (i as u64 + 1) + latency_us, At::Push(b)));
                    }
                    own_bytes += own.len();
                    t += BYTE_US * own.len() as u64 + latency_us;
                }
                Err(item) => {
                    let bytes = item.bytes();
                    for (i, &b) in bytes.iter().enumerate() {
                        events.push((t + BYTE_US * (i as u64 + 1), At::Push(b)));
                    }
                    foreign.extend_from_slice(&bytes);
                    t += BYTE_US * bytes.len() as u64;
                }
            }
            // Every station leaves the wire quiet before it talks.
            t += BUS_QUIET_BEFORE_SEND_US;
        }
        events.extend(polls.into_iter().map(|p| (p, At::Tick)));
        let mut out = play(&mut rx, events);
        rx.on_time(u64::MAX, &mut |h| out.take(h));
        prop_assert_eq!(&out.bytes, &foreign);
        prop_assert_eq!(rx.echo_bytes() as usize, own_bytes);
        prop_assert!(out.verdicts.iter().all(|v| *v == Echo::Whole), "{:?}", out.verdicts);
        prop_assert!(!rx.take_collision());
        // Other stations' frames and packets all come out (and whatever else their bytes hold).
        let want_frames: Vec<Frame> = script
            .iter()
            .filter_map(|e| match e { Err(Item::Frame(f)) => Some(f.clone()), _ => None })
            .collect();
        let want_packets: Vec<Packet> = script
            .iter()
            .filter_map(|e| match e { Err(Item::Packet(p)) => Some(p.clone()), _ => None })
            .collect();
        prop_assert!(in_order(&out.frames, &want_frames), "{:?} in {:?}", want_frames, out.frames);
        prop_assert!(in_order(&out.packets, &want_packets), "{:?} in {:?}", want_packets, out.packets);
        for f in &out.frames {
            prop_assert!(contains(&foreign, &f.to_bytes()), "{:?} is not another station's", f);
        }
        for p in &out.packets {
            prop_assert!(contains(&foreign, &p.to_bytes()), "{:?} is not another station's", p);
        }
    }
    #[test]
    fn a_host_frame_inside_a_servo_packet_is_never_heard(
        items in prop::collection::vec(
            prop_oneof![2 => packet_around_a_frame(), 1 => any_item()],
            1..10,
        ),
        gaps_us in prop::collection::vec(BUS_QUIET_BEFORE_SEND_US..2 * BUS_FRAME_GAP_US, 10),
        polls in prop::collection::vec(0u64..20_000, 0..60),
    ) {
        let mut rx = Listener::default();
        let mut events = Vec::new();
        let mut t = 100;
        for (item, gap_us) in items.iter().zip(&gaps_us) {
            for b in item.bytes() {
                t += BYTE_US;
                events.push((t, At::Push(b)));
            }
            t += gap_us;
        }
        events.extend(polls.into_iter().map(|p| (p, At::Tick)));
        let mut out = play(&mut rx, events);
        rx.on_time(u64::MAX, &mut |h| out.take(h));
        // Exactly the frames sent as frames: none from a packet's data, none lost.
        let want_frames: Vec<Frame> = items
            .iter()
            .filter_map(|i| match i { Item::Frame(f) => Some(f.clone()), _ => None })
            .collect();
        prop_assert_eq!(&out.frames, &want_frames);
        let want_packets: Vec<Packet> = items
            .iter()
            .filter_map(|i| match i { Item::Packet(p) => Some(p.clone()), _ => None })
            .collect();
        prop_assert!(in_order(&out.packets, &want_packets), "{:?} in {:?}", want_packets, out.packets);
    }

    #[test]
    fn an_answer_read_late_on_a_line_without_echo_is_always_heard(
        rounds in prop::collection::vec(
            (any_item(), prop_oneof![Just(None), any_item().prop_map(Some)], 0u64..5_000),
            1..8,
        ),
        echo in prop_oneof![Just(EchoMode::Auto), Just(EchoMode::Absent)],
    ) {
        let mut rx = Listener::new(ListenerConfig::new().with_bytes(true).with_echo(echo));
        let mut out = Out::default();
        // Auto learns that the line is silent from a first transmission.
        rx.on_transmit(0, &[0x55]);
        rx.on_time(1_000, &mut |h| out.take(h));
        let mut answers = Vec::new();
        let mut t = 10_000;
        for (sent, other, stall_us) in &rounds {
            // The answer: the transmission itself (a reply that repeats its request), or another.
            let answer = other.clone().unwrap_or_else(|| sent.clone());
            let sent = sent.bytes();
            rx.on_transmit(t, &sent);
            // No poll from the transmission until the answer is read, after its echo window.
            t += BYTE_US * sent.len() as u64 + ECHO_GRACE_US + stall_us;
            for b in answer.bytes() {
                rx.push(t, b, &mut |h| out.take(h));
            }
            t += 2 * BUS_FRAME_GAP_US;
            rx.on_time(t, &mut |h| out.take(h));
            answers.push(answer);
        }
        prop_assert_eq!(rx.echo_bytes(), 0);
        prop_assert!(!rx.take_collision());
        let all: Vec<u8> = answers.iter().flat_map(Item::bytes).collect();
        prop_assert_eq!(&out.bytes, &all);
        for answer in &answers {
            match answer {
                Item::Frame(f) => prop_assert!(out.frames.contains(f), "{:?} lost", f),
                Item::Packet(p) => prop_assert!(out.packets.contains(p), "{:?} lost", p),
            }
        }
    }
}

//! Properties over arbitrary input: no panic, and exactly one reply per request whatever the
//! chunking of the host stream and whatever else travels on the bus.
#![allow(clippy::unwrap_used, clippy::indexing_slicing)]

mod common;

#[path = "../../firmware-atom/tests/replay_seeds/mod.rs"]
mod replay_seeds;
use replay_seeds::ReplaySeeds;

use common::{BUS_BYTE_NS, HOST_BYTE_NS, Rig, frame, pymycobot_reads};
use firmware_basic::{Basic, BasicConfig, EchoMode, NullIo};
use proptest::prelude::*;
use protocol_core::{BytePort, Frame};

/// A port that hands out scripted bytes and accepts anything; its transmitter is idle when
/// the script says so.
struct ScriptPort {
    rx: std::collections::VecDeque<u8>,
    idle: bool,
    written: Vec<u8>,
}

impl BytePort for ScriptPort {
    fn read_byte(&mut self) -> Option<u8> {
        self.rx.pop_front()
    }
    fn write(&mut self, bytes: &[u8]) {
        self.written.extend_from_slice(bytes);
    }
    fn tx_idle(&self) -> bool {
        self.idle
    }
}

/// True if `part` is `whole` with some elements left out, the rest in order.
fn is_subsequence(part: &[u8], whole: &[u8]) -> bool {
    let mut rest = whole.iter();
    part.iter().all(|p| rest.any(|w| w == p))
}

fn echo_mode() -> impl Strategy<Value = EchoMode> {
    prop_oneof![
        Just(EchoMode::Auto),
        Just(EchoMode::Present),
        Just(EchoMode::Absent)
    ]
}

/// A byte stream rich in frame bytes, so that frames and near-frames occur often.
fn stream() -> impl Strategy<Value = Vec<u8>> {
    prop::collection::vec(
        prop_oneof![
            Just(0xFEu8),
            Just(0xFA),
            Just(0xFF),
            Just(0xC2),
            Just(0x01),
            Just(0x00),
            Just(0x03),
            any::<u8>()
        ],
        0..200,
    )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: std::env::var("PROPTEST_CASES").ok().and_then(|c| c.parse().ok()).unwrap_or(128), failure_persistence: Some(Box::new(ReplaySeeds(include_str!("properties.proptest-regressions")))), ..ProptestConfig::default() })]

    /// Any bytes on either side, any timing, any transmitter state: the Basic never panics,
    /// and afterwards it still answers: "set framed mode" then "get Basic version" get their
    /// replies whatever state the garbage left it in.
    #[test]
    fn never_panics_on_any_input(
        host_bytes in stream(),
        bus_bytes in stream(),
        steps in prop::collection::vec((0u64..5_000, 0usize..16, any::<bool>()), 1..80),
        echo in echo_mode(),
        boot_us in prop_oneof![Just(0u64), any::<u64>().prop_map(|t| t / 2)],
    ) {
        let config = BasicConfig { echo, boot_power_on_delay_us: 1_000, ..BasicConfig::default() };
        let mut basic = Basic::new(config);
        let mut host = ScriptPort { rx: host_bytes.into(), idle: true, written: Vec::new() };
        let mut bus = ScriptPort { rx: Default::default(), idle: true, written: Vec::new() };
        let mut bus_src = bus_bytes.into_iter();
        // The board's clock may read anything at boot.
        let mut now = boot_us;
        for (dt, bus_n, idle) in steps {
            now += dt;
            bus.rx.extend(bus_src.by_ref().take(bus_n));
            bus.idle = idle;
            host.idle = !idle;
            basic.poll(now, &mut host, &mut bus, &mut NullIo);
        }
        // Drain everything with idle transmitters and far-away deadlines.
        host.idle = true;
        bus.idle = true;
        bus.rx.extend(bus_src);
        for _ in 0..50 {
            now += 100_000;
            basic.poll(now, &mut host, &mut bus, &mut NullIo);
        }
        host.written.clear();
        host.rx.extend(frame(0xC2, &[0]));
        host.rx.extend(frame(0xC1, &[]));
        for _ in 0..20 {
            now += 1_000;
            basic.poll(now, &mut host, &mut bus, &mut NullIo);
        }
        let mut expected = frame(0xC2, &[1]);
        expected.extend(frame(0xC1, &[10]));
        prop_assert!(host.written.ends_with(&expected), "{:02x?}", host.written);
    }

    /// Requests arriving in arbitrary pieces (gaps shorter than the frame gap) reach the Atom
    /// at most once each, in order, and the host gets exactly one reply for each request the
    /// Atom got, in order - with or without echo, whatever the Atom's turnaround, with servo
    /// traffic (no `FE` bytes) on the bus meanwhile.
    ///
    /// With echo every request gets through: a collision shows in the echo and the request
    /// is sent again - once the Basic knows the line echoes. It learns that from its first
    /// whole echo (`EchoMode::Auto`); before that a differing echo may as well be an answer, so
    /// noise on its very first transmission cannot show (listener.rs, `Echo::Differed`). The
    /// rig therefore sends one request first, before the noise can start. Without echo, noise that overlaps only the end of a request (it starts
    /// during the Basic's last byte and ends after it) garbles the request at the Atom while
    /// nothing reaches the Basic before its transmission is over, so nothing can show it the
    /// collision: such a request is lost. The Basic then waits its reply timeout, counts the
    /// timeout and goes on with the next request; the client sends again after its own
    /// deadline (pymycobot: 0.5 s). So the run lasts past the reply timeout, and the
    /// property is: no request twice, no reply without its request, every lost request
    /// counted as a timeout, and the next request afterwards answered.
    #[test]
    fn one_reply_per_request_under_any_chunking(
        cmds in prop::collection::vec(
            prop_oneof![Just(0x20u8), Just(0x12), Just(0x2B), Just(0x23), Just(0xD5), Just(0x62)],
            1..5,
        ),
        cuts in prop::collection::vec((1usize..6, 0u64..1_500), 0..20),
        noise in prop::collection::vec(0u8..0xF0, 0..40),
        noise_at_us in 0u64..20_000,
        echo in any::<bool>(),
        atom_delay_us in 0u64..400,
    ) {
        let mut rig = Rig::quiet(echo);
        rig.step_ns = 2_000;
        rig.atom_delay_ns = atom_delay_us * 1_000;
        // The first request (0x29, none of `cmds`): the Basic hears its echo, if there is one.
        rig.host.send(&frame(0x29, &[]));
        rig.run_us(5_000);
        let primed = rig.host_frames().len();
        prop_assert_eq!(primed, 1);
        let mut bytes = Vec::new();
        for &c in &cmds {
            bytes.extend(frame(c, &[]));
        }
        let start_ns = rig.now_ns;
        rig.wire().inject(start_ns + noise_at_us * 1_000, &noise);
        let mut rest = bytes.as_slice();
        for (len, gap_us) in cuts {
            if rest.is_empty() {
                break;
            }
            let (chunk, tail) = rest.split_at(len.min(rest.len()));
            rig.host.send(chunk);
            rest = tail;
            rig.run_us(gap_us + chunk.len() as u64 * HOST_BYTE_NS / 1_000);
        }
        rig.host.send(rest);
        rig.run_us(60_000 + bytes.len() as u64 * HOST_BYTE_NS / 1_000);
        if rig.host_frames().len() < primed + cmds.len() {
            // A request was lost: let the Basic's reply timeout pass (at a coarser poll,
            // only to save test time) and the requests behind it go.
            rig.step_ns = 10_000;
            rig.run_us(BasicConfig::default().reply_timeout_us + 20_000);
        }
        let replied: Vec<u8> = rig.host_frames().iter().skip(primed).map(Frame::cmd).collect();
        // A collision with the noise corrupts a copy: the Atom cannot decode it, or (host
        // frames carry no checksum) decodes another command, which no request matches. It
        // never gets two intact copies of one request, nor the host two replies.
        let delivered: Vec<u8> = rig
            .atom_got
            .iter()
            .map(|(_, f)| f.cmd())
            .filter(|c| cmds.contains(c))
            .collect();
        prop_assert!(is_subsequence(&delivered, &cmds), "{:02x?} of {:02x?}", delivered, cmds);
        prop_assert_eq!(&replied, &delivered);
        let lost = cmds.len() - delivered.len();
        if echo {
            prop_assert_eq!(lost, 0, "with echo every collision shows");
        }
        prop_assert_eq!(rig.basic.status().timeouts as usize, lost);
        // Not wedged: the client's next request is answered.
        rig.step_ns = 2_000;
        rig.host.send(&frame(0x12, &[]));
        rig.run_us(10_000);
        prop_assert_eq!(rig.host_frames().len(), primed + delivered.len() + 1);
    }

    /// Whatever noise hits the Atom's replies (the scripted Atom's, with `FE` and `FA` in their
    /// data), a serial client finds the same frames in what it receives whether the Basic
    /// passes each reply on as it arrives (cut-through) or only once it is complete, with
    /// protocol-core's decoder and with pymycobot's parser: passing on early never makes a
    /// frame, nor loses one. The bus traffic is the same either way (cut-through changes only
    /// what goes to the client), so the noise hits the same bytes.
    #[test]
    fn cut_through_gives_a_client_the_frames_a_whole_reply_gives(
        cmds in prop::collection::vec(prop_oneof![Just(0x20u8), Just(0x12), Just(0x23)], 1..4),
        hits in prop::collection::vec((0u64..40, prop::collection::vec(any::<u8>(), 1..6)), 1..4),
        echo in any::<bool>(),
        atom_delay_us in 0u64..300,
    ) {
        let run = |cut_through: bool| {
            let mut rig = Rig::new(
                BasicConfig {
                    power_on_at_boot: false,
                    probe_interval_us: 0,
                    cut_through,
                    ..BasicConfig::default()
                },
                echo,
            );
            rig.step_ns = 2_000;
            rig.atom_delay_ns = atom_delay_us * 1_000;
            for (i, &c) in cmds.iter().enumerate() {
                rig.host.send(&frame(c, &[]));
                // The scripted Atom keeps clear of traffic it knows is coming: the noise is
                // scheduled once its reply is on the wire.
                let until = rig.now_ns + 20_000_000;
                while rig.atom_sent.len() <= i && rig.now_ns < until {
                    rig.step();
                }
                if let (Some((start, _)), Some((offset, noise))) = (rig.atom_sent.get(i), hits.get(i)) {
                    let at = *start + offset * BUS_BYTE_NS / 2;
                    rig.wire().inject(at, noise);
                }
                rig.run_us(5_000);
            }
            rig.run_us(BasicConfig::default().reply_timeout_us + 10_000);
            (rig.host_frames(), pymycobot_reads(&rig.host.received()), rig.atom_got.len())
        };
        let (whole, whole_py, whole_sent) = run(false);
        let (early, early_py, early_sent) = run(true);
        prop_assert_eq!(whole_sent, early_sent, "the same bus traffic");
        prop_assert_eq!(&early, &whole);
        prop_assert_eq!(&early_py, &whole_py);
    }
}

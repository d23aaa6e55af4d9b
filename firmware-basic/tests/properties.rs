//! Properties over arbitrary input: no panic, and exactly one reply per request whatever the
//! chunking of the host stream and whatever else travels on the bus.
#![allow(clippy::unwrap_used, clippy::indexing_slicing)]

mod common;

use common::{HOST_BYTE_NS, Rig, frame};
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
    #![proptest_config(ProptestConfig { cases: 128, ..ProptestConfig::default() })]

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

    /// Requests arriving in arbitrary pieces (gaps shorter than the frame gap) each reach the
    /// Atom once, in order, and each reply reaches the host once, in order - with or without
    /// echo, whatever the Atom's turnaround, with servo traffic (no `FE` bytes) on the bus
    /// meanwhile.
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
        let mut bytes = Vec::new();
        for &c in &cmds {
            bytes.extend(frame(c, &[]));
        }
        rig.wire().inject(noise_at_us * 1_000, &noise);
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
        let replied: Vec<u8> = rig.host_frames().iter().map(Frame::cmd).collect();
        // A collision with the noise corrupts a copy: the Atom cannot decode it, or (host
        // frames carry no checksum) decodes another command, which no request matches. It
        // never gets two intact copies of one request, nor the host two replies.
        let delivered: Vec<u8> = rig
            .atom_got
            .iter()
            .map(|(_, f)| f.cmd())
            .filter(|c| cmds.contains(c))
            .collect();
        prop_assert_eq!(&delivered, &cmds);
        prop_assert_eq!(&replied, &cmds);
    }
}

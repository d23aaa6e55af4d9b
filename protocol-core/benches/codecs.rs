//! Decoder throughput on a realistic mixed wire stream, and per-frame codec costs.
//!
//! The stream is what the shared bus and a busy host link carry: host requests and replies
//! (get_angles, send_angles, send_coords, jog...), STS servo traffic (SYNC WRITE of goal
//! positions, READ of the present-state block and its status answers) and line noise.
//! Run: `cargo bench -p protocol-core --bench codecs`.

// Bench code: a panic is a failed run.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    missing_docs
)]

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use protocol_core::command::{Reply, Request, cmd};
use protocol_core::servo::{Instruction, Packet, PacketDecoder, SyncWriteBuilder, reg};
use protocol_core::units::{Centideg, SpeedPercent};
use protocol_core::{Frame, FrameDecoder};

/// A deterministic xorshift generator, so every run measures the same stream.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    fn byte(&mut self) -> u8 {
        (self.next() >> 24) as u8
    }
}

fn host_frames() -> Vec<Frame> {
    let speed = SpeedPercent::new(50).unwrap();
    let angles = [-16800, -2, 250, 0, 12345, 18000].map(Centideg);
    let reqs = [
        Request::GetAngles,
        Request::SendAngles { angles, speed },
        Request::GetCoords,
        Request::IsMoving,
        Request::SendCoords {
            pose: protocol_core::command::Pose::from_array([1565, -634, 3042, -17560, -6, -8990]),
            speed,
            mode: None,
        },
    ];
    let mut frames: Vec<Frame> = reqs.iter().map(Request::to_frame).collect();
    frames.push(Reply::Angles(angles).to_frame(cmd::GET_ANGLES));
    frames.push(Reply::Ack.to_frame(cmd::SEND_ANGLES));
    frames
}

fn servo_packets() -> Vec<Packet> {
    let mut sync = SyncWriteBuilder::new(reg::GOAL_POSITION, 6);
    for id in 1..=6u8 {
        sync.push(id, &[0x00, 0x08, 0, 0, 0xE8, 0x03]).unwrap();
    }
    let read = Instruction::Read {
        addr: reg::PRESENT_POSITION,
        count: 15,
    };
    let mut out = vec![sync.to_packet().unwrap()];
    for id in 1..=6u8 {
        out.push(read.to_packet(id).unwrap());
        out.push(
            Packet::new(
                id,
                0,
                &[0x00, 0x08, 0, 0, 0, 0, 0x78, 0x1E, 0, 0, 0, 0, 0, 0, 0],
            )
            .unwrap(),
        );
    }
    out
}

/// About 1 MB of mixed traffic: host frames, servo packets and noise bursts.
fn mixed_stream() -> Vec<u8> {
    let frames: Vec<Vec<u8>> = host_frames()
        .iter()
        .map(|f| f.to_bytes().to_vec())
        .collect();
    let packets: Vec<Vec<u8>> = servo_packets()
        .iter()
        .map(|p| p.to_bytes().to_vec())
        .collect();
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    let mut out = Vec::with_capacity(1 << 20);
    while out.len() < 1 << 20 {
        match rng.next() % 10 {
            0..=3 => out.extend_from_slice(&frames[(rng.next() % frames.len() as u64) as usize]),
            4..=8 => out.extend_from_slice(&packets[(rng.next() % packets.len() as u64) as usize]),
            _ => {
                for _ in 0..rng.next() % 16 {
                    out.push(rng.byte());
                }
            }
        }
    }
    out
}

fn decoders(c: &mut Criterion) {
    let stream = mixed_stream();
    let mut g = c.benchmark_group("mixed_stream");
    g.throughput(Throughput::Bytes(stream.len() as u64));
    g.bench_function("frame_decoder", |b| {
        b.iter(|| {
            let mut d = FrameDecoder::new();
            let mut n = 0u32;
            d.feed(black_box(&stream), |f| n += u32::from(f.cmd()));
            n
        })
    });
    g.bench_function("frame_decoder_and_parse", |b| {
        b.iter(|| {
            let mut d = FrameDecoder::new();
            let mut n = 0u32;
            d.feed(black_box(&stream), |f| {
                n += u32::from(Request::parse(&f).is_ok())
            });
            n
        })
    });
    g.bench_function("packet_decoder", |b| {
        b.iter(|| {
            let mut d = PacketDecoder::new();
            let mut n = 0u32;
            d.feed(black_box(&stream), |p| n += u32::from(p.id()));
            n
        })
    });
    g.finish();
}

fn per_frame(c: &mut Criterion) {
    let req = Request::SendAngles {
        angles: [-16800, -2, 250, 0, 12345, 18000].map(Centideg),
        speed: SpeedPercent::new(50).unwrap(),
    };
    let frame = req.to_frame();
    let bytes = frame.to_bytes();
    let mut g = c.benchmark_group("send_angles_frame");
    g.bench_function("encode_request", |b| b.iter(|| black_box(&req).to_frame()));
    g.bench_function("frame_to_bytes", |b| {
        b.iter(|| black_box(&frame).to_bytes())
    });
    g.bench_function("decode_bytes", |b| {
        b.iter(|| {
            let mut d = FrameDecoder::new();
            let mut out = None;
            d.feed(black_box(&bytes), |f| out = Some(f));
            out
        })
    });
    g.bench_function("parse_request", |b| {
        b.iter(|| Request::parse(black_box(&frame)))
    });
    g.bench_function("encode_reply", |b| {
        b.iter(|| Reply::Angles(black_box([Centideg(1); 6])).to_frame(cmd::GET_ANGLES))
    });
    g.finish();
}

criterion_group!(benches, decoders, per_frame);
criterion_main!(benches);

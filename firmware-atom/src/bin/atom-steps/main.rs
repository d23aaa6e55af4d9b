//! What one pass of the Atom's loop costs on the chip, for the steps that cost the most.
//!
//! The Atom's real loop ([`firmware_atom::Atom::poll`]) runs against servos inside the image
//! ([`servos`]) and a scripted host link, and each pass is timed with the CPU's cycle counter.
//! Step by step (the idle state refresh, a joint move, forward and inverse kinematics, a
//! straight line, an arc, a 50 Hz stream, a backup and a restore of every servo) it prints the
//! cost of the pass that takes the command and of the longest other pass on UART0:
//!
//! ```text
//! step line: passes 48154, first 60011 cycles, longest other 735674 cycles (pass 47439), mean 3425, reply [01], error 0
//! clock: 120004102 cycles in 500017 us
//! ```
//!
//! On a chip the cycles are the CPU's (240 MHz). `tests/emulated.rs` runs the image on the
//! emulated ESP32 with a fixed time per instruction (`-icount`), where the last line turns the
//! cycles into instructions, and checks each step against its budget (docs/boards.md, "Loop
//! passes on the chip"). Build it with `.ci/link-esp32 --only atom-steps`.
#![no_std]
#![no_main]
#![deny(unsafe_code)]

#[cfg(not(target_os = "none"))]
compile_error!("the atom-steps binary builds only for a chip: `.ci/link-esp32 --only atom-steps`");

mod servos;

use board_support::pass_cost::{PassCost, cycles};
use board_support::{board_log, now_us};
use esp_hal::{clock::CpuClock, main};
use firmware_atom::{Atom, AtomConfig, RecordingIo};
use heapless::Deque;
use protocol_core::command::{MoveMode, Pose, Request, ServoSelect};
use protocol_core::units::{Centideg, DeciMm, SpeedPercent};
use protocol_core::{BytePort, Frame, FrameDecoder};

use crate::servos::ServoBus;

esp_bootloader_esp_idf::esp_app_desc!();

/// The host link as the Atom's UART0 sees it: frames queued for the Atom, its replies kept.
struct HostLink {
    to_atom: Deque<u8, 256>,
    decoder: FrameDecoder,
    last_reply: Option<Frame>,
}

impl BytePort for HostLink {
    fn read_byte(&mut self) -> Option<u8> {
        self.to_atom.pop_front()
    }

    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            let mut found = self.decoder.push(b);
            while let Some(frame) = found {
                self.last_reply = Some(frame);
                found = self.decoder.next_frame();
            }
        }
    }

    fn tx_idle(&self) -> bool {
        true
    }
}

struct Bench {
    atom: Atom,
    bus: ServoBus,
    host: HostLink,
    io: RecordingIo,
}

impl Bench {
    fn send(&mut self, request: &Request) {
        self.host.last_reply = None;
        for b in request.to_frame().to_bytes() {
            self.host.to_atom.push_back(b).ok();
        }
    }

    /// One pass of the Atom's loop; its cycles.
    fn pass(&mut self) -> u32 {
        let now = now_us();
        self.bus.run_to(now);
        let start = cycles();
        self.atom
            .poll(now, &mut self.bus, &mut self.host, &mut self.io);
        cycles().wrapping_sub(start)
    }

    /// Passes for `span_us`, then on until `done` holds (at most `limit_us` in all).
    fn run(&mut self, span_us: u64, limit_us: u64, done: impl Fn(&Self) -> bool) -> PassCost {
        let start = now_us();
        let mut cost = PassCost::default();
        loop {
            cost.add(self.pass());
            let elapsed = now_us().saturating_sub(start);
            if (elapsed >= span_us && done(self)) || elapsed >= limit_us {
                return cost;
            }
        }
    }

    /// Sends `request`, runs until its reply is in and the arm is at rest (or `span_us` has
    /// passed, for what does not move), and prints the step's cost.
    fn step(&mut self, name: &str, request: &Request, span_us: u64) {
        self.send(request);
        let cost = self.run(span_us, 20_000_000, |b| {
            b.host.last_reply.is_some() && !b.atom.is_moving()
        });
        self.print(name, &cost);
    }

    fn print(&self, name: &str, cost: &PassCost) {
        let reply = self.host.last_reply.as_ref();
        board_log!(
            "step {}: passes {}, first {} cycles, longest other {} cycles (pass {}), mean {}, reply {:02x?}, error {}",
            name,
            cost.passes,
            cost.first,
            cost.longest,
            cost.longest_at,
            cost.mean(),
            reply.map(|f| f.data()).unwrap_or(&[]),
            self.atom.error_code()
        );
    }

    /// The pose the Atom reports (0x23).
    fn coords(&mut self) -> [i16; 6] {
        self.send(&Request::GetCoords);
        self.run(0, 1_000_000, |b| b.host.last_reply.is_some());
        let data = self
            .host
            .last_reply
            .as_ref()
            .map(|f| f.data())
            .unwrap_or(&[]);
        core::array::from_fn(|i| {
            let at = |k: usize| data.get(2 * i + k).copied().unwrap_or(0);
            i16::from_be_bytes([at(0), at(1)])
        })
    }
}

/// A pose from wire units (0.1 mm, 0.01 deg) moved by `dx`, `dy`, `dz` millimetres.
fn pose(at: [i16; 6], dx: i16, dy: i16, dz: i16) -> Pose {
    Pose {
        x: DeciMm(at[0].saturating_add(dx * 10)),
        y: DeciMm(at[1].saturating_add(dy * 10)),
        z: DeciMm(at[2].saturating_add(dz * 10)),
        rx: Centideg(at[3]),
        ry: Centideg(at[4]),
        rz: Centideg(at[5]),
    }
}

fn degrees(values: [i16; 6]) -> [Centideg; 6] {
    values.map(|d| Centideg(d.saturating_mul(100)))
}

#[main]
fn main() -> ! {
    let p = esp_hal::init(esp_hal::Config::default().with_cpu_clock(CpuClock::max()));
    board_support::clock::start(&p);
    board_log!("atom-steps {}", env!("CARGO_PKG_VERSION"));
    let speed = SpeedPercent::new(50).unwrap_or(SpeedPercent::MAX);
    let mut bench = Bench {
        atom: Atom::new(AtomConfig::default()),
        bus: ServoBus::new(),
        host: HostLink {
            to_atom: Deque::new(),
            decoder: FrameDecoder::new(),
            last_reply: None,
        },
        io: RecordingIo::default(),
    };
    // The clock over the idle step (half a second: the 32-bit counter does not wrap).
    let (start_cycles, start_us) = (cycles(), now_us());
    let idle = bench.run(500_000, 500_000, |_| true);
    let clock_cycles = cycles().wrapping_sub(start_cycles);
    let clock_us = now_us() - start_us;
    bench.print("idle", &idle);
    board_log!("refresh rounds: {}", bench.atom.refresh_rounds());
    bench.step("power on", &Request::PowerOn, 50_000);
    // Where a 40 mm circle fits around the flange in every direction (tests/sim_arc.rs).
    let home = degrees([10, -30, -50, -10, 10, 20]);
    let joint_move = Request::SendAngles {
        angles: home,
        speed,
    };
    bench.step("joint move", &joint_move, 50_000);
    bench.step("forward kinematics", &Request::GetCoords, 0);
    let here = bench.coords();
    let arc = Request::MoveCCoordsFromHere {
        middle: pose(here, -40, 40, 10),
        end: pose(here, 0, 80, 0),
    };
    bench.step("arc", &arc, 50_000);
    bench.send(&joint_move);
    bench.run(50_000, 20_000_000, |b| !b.atom.is_moving());
    let here = bench.coords();
    let ik_move = Request::SendCoords {
        pose: pose(here, -20, 0, 0),
        speed,
        mode: Some(MoveMode::Joint),
    };
    bench.step("inverse kinematics move", &ik_move, 50_000);
    let here = bench.coords();
    let line = Request::SendCoords {
        pose: pose(here, 40, 0, -30),
        speed,
        mode: Some(MoveMode::Linear),
    };
    bench.step("line", &line, 50_000);

    // A 50 Hz stream of send_angles: joint 1 swept back and forth by 20 degrees.
    let mut stream = PassCost::default();
    for sample in 0..100i16 {
        let swing = if sample % 50 < 25 {
            sample % 25
        } else {
            25 - sample % 25
        };
        let angles = degrees([10 + swing * 4 / 5, -30, -50, -10, 10, 20]);
        bench.send(&Request::SendAngles {
            angles,
            speed: SpeedPercent::MAX,
        });
        let leg = bench.run(20_000, 20_000, |_| true);
        stream.extend(&leg);
    }
    bench.print("stream", &stream);
    let rest = bench.run(50_000, 5_000_000, |b| !b.atom.is_moving());
    bench.print("stream end", &rest);

    let all = ServoSelect::All;
    bench.step(
        "backup",
        &Request::BackupServoParams { servo: all },
        100_000,
    );
    bench.step(
        "restore",
        &Request::RestoreServoParams { servo: all },
        100_000,
    );

    board_log!("clock: {} cycles in {} us", clock_cycles, clock_us);
    board_log!("atom-steps: done");
    loop {
        core::hint::spin_loop();
    }
}

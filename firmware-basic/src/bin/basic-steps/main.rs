//! What one pass of the Basic's loop costs on the chip, for the steps that cost the most.
//!
//! The Basic's real loop ([`firmware_basic::Basic::poll`], and the status screen's text as the
//! board renders it every 100 ms) runs against a bus with a busy Atom on it ([`atom`]) and a
//! scripted USB link at 115 200 baud, and each pass is timed with the CPU's cycle counter.
//! Step by step (listening to the Atom's servo refresh, `get_angles` forwarded, a 50 Hz stream
//! of `send_angles`, the Basic's own commands, the manual's dialect, garbage on the USB link)
//! it prints the longest pass on UART0:
//!
//! ```text
//! step get_angles: passes 52011, longest 9214 cycles (pass 301), mean 1210, replies 100 of 100, forwarded 100
//! clock: 120004102 cycles in 500017 us
//! ```
//!
//! `tests/emulated.rs` runs the image on the emulated ESP32 with a fixed time per instruction
//! (`-icount`) and checks each step against its budget (docs/boards.md, "Loop passes on the
//! chip"). Build it with `.ci/link-esp32 --only basic-steps`.
#![no_std]
#![no_main]
#![deny(unsafe_code)]

#[cfg(not(target_os = "none"))]
compile_error!(
    "the basic-steps binary builds only for a chip: `.ci/link-esp32 --only basic-steps`"
);

mod atom;
mod line;
#[allow(dead_code)]
#[path = "../basic/radio_start.rs"]
mod radio_start;
#[allow(dead_code)]
#[path = "../basic/screen_text.rs"]
mod screen_text;

use board_support::pass_cost::{PassCost, cycles};
use board_support::{board_log, now_us};
use esp_hal::{clock::CpuClock, main};
use firmware_basic::{Basic, BasicConfig, NullIo};
use protocol_core::command::cmd;
use protocol_core::timing::HOST_BAUD;
use protocol_core::{BytePort, Frame, FrameDecoder};

use crate::atom::AtomBus;
use crate::line::Line;
use crate::screen_text::BoardStatus;

esp_bootloader_esp_idf::esp_app_desc!();

/// How often the board renders the status screen's text (screen.rs).
const RENDER_EVERY_US: u64 = 100_000;
/// How long a step waits for a reply before it sends the next request.
const REPLY_DEADLINE_US: u64 = 100_000;

/// The USB link: bytes for the Basic at 115 200 baud, its replies counted.
struct HostLink {
    now_us: u64,
    to_basic: Line<512>,
    decoder: FrameDecoder,
    replies: u32,
}

impl HostLink {
    /// Queues `bytes` as a client writes them: back to back from now (or after what is queued).
    fn send(&mut self, bytes: &[u8]) {
        self.to_basic.send(self.now_us, bytes);
    }
}

impl BytePort for HostLink {
    fn read_byte(&mut self) -> Option<u8> {
        self.to_basic.take(self.now_us)
    }

    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            let mut found = self.decoder.push(b);
            while found.is_some() {
                self.replies += 1;
                found = self.decoder.next_frame();
            }
        }
    }

    fn tx_idle(&self) -> bool {
        true
    }
}

struct Bench {
    basic: Basic,
    bus: AtomBus,
    host: HostLink,
    rendered_us: u64,
}

impl Bench {
    /// One pass of the Basic's loop (and the status text when due); its cycles.
    fn pass(&mut self) -> u32 {
        let now = now_us();
        self.bus.run_to(now);
        self.host.now_us = now;
        let start = cycles();
        self.basic
            .poll(now, &mut self.host, &mut self.bus, &mut NullIo);
        if now.saturating_sub(self.rendered_us) >= RENDER_EVERY_US {
            self.rendered_us = now;
            let board = BoardStatus {
                loop_max_us: 0,
                wifi: None,
                radio: None,
            };
            core::hint::black_box(screen_text::render(&self.basic.status(), &board));
        }
        cycles().wrapping_sub(start)
    }

    /// Passes for `span_us`.
    fn run(&mut self, span_us: u64, cost: &mut PassCost) {
        let start = now_us();
        while now_us().saturating_sub(start) < span_us {
            cost.add(self.pass());
        }
    }

    /// Sends `frame` `times` times, each once the reply to the one before is in and `every_us`
    /// after it (or after [`REPLY_DEADLINE_US`] without a reply), and prints the step's cost.
    fn step(&mut self, name: &str, frame: &[u8], times: u32, every_us: u64) {
        let (replies, forwarded) = (self.host.replies, self.bus.forwarded);
        let mut cost = PassCost::default();
        for _ in 0..times {
            let before = self.host.replies;
            self.host.send(frame);
            let start = now_us();
            loop {
                cost.add(self.pass());
                let elapsed = now_us().saturating_sub(start);
                if (self.host.replies > before && elapsed >= every_us)
                    || elapsed >= REPLY_DEADLINE_US
                {
                    break;
                }
            }
        }
        self.print(
            name,
            &cost,
            self.host.replies - replies,
            times,
            self.bus.forwarded - forwarded,
        );
    }

    fn print(&self, name: &str, cost: &PassCost, replies: u32, asked: u32, forwarded: u32) {
        let (longest, at) = cost.worst();
        board_log!(
            "step {}: passes {}, longest {} cycles (pass {}), mean {}, replies {} of {}, forwarded {}",
            name,
            cost.passes,
            longest,
            at,
            cost.mean(),
            replies,
            asked,
            forwarded
        );
    }
}

fn frame(cmd: u8, data: &[u8]) -> heapless::Vec<u8, 64> {
    Frame::new(cmd, data)
        .map(|f| f.to_bytes().iter().copied().collect())
        .unwrap_or_default()
}

#[main]
fn main() -> ! {
    let p = esp_hal::init(esp_hal::Config::default().with_cpu_clock(CpuClock::max()));
    board_support::clock::start(&p);
    board_log!("basic-steps {}", env!("CARGO_PKG_VERSION"));
    let mut bench = Bench {
        basic: Basic::new(BasicConfig::default()),
        bus: AtomBus::new(),
        host: HostLink {
            now_us: 0,
            to_basic: Line::new(HOST_BAUD),
            decoder: FrameDecoder::new(),
            replies: 0,
        },
        rendered_us: 0,
    };
    // The clock over the idle step (half a second: the 32-bit counter does not wrap).
    let (start_cycles, start_us) = (cycles(), now_us());
    let mut idle = PassCost::default();
    bench.run(500_000, &mut idle);
    let clock_cycles = cycles().wrapping_sub(start_cycles);
    let clock_us = now_us() - start_us;
    bench.print("idle", &idle, 0, 0, 0);

    bench.step("get_angles", &frame(cmd::GET_ANGLES, &[]), 100, 0);
    // A 50 Hz stream: joint 1 at 10 degrees and on by a tenth a sample (centidegrees, BE).
    let mut stream = PassCost::default();
    let (replies, forwarded) = (bench.host.replies, bench.bus.forwarded);
    for sample in 0..100i16 {
        let mut data = [0u8; 13];
        let angle = (1_000 + sample * 10).to_be_bytes();
        data[0] = angle[0];
        data[1] = angle[1];
        data[12] = 50;
        bench.host.send(&frame(cmd::SEND_ANGLES, &data));
        bench.run(20_000, &mut stream);
    }
    bench.print(
        "send_angles at 50 Hz",
        &stream,
        bench.host.replies - replies,
        100,
        bench.bus.forwarded - forwarded,
    );
    bench.step(
        "get_basic_version",
        &frame(cmd::GET_BASIC_VERSION, &[]),
        50,
        0,
    );
    bench.step(
        "get_basic_input",
        &frame(cmd::GET_BASIC_INPUT, &[35]),
        50,
        0,
    );
    bench.step("to the seed dialect", &frame(cmd::DIALECT, &[2]), 1, 0);
    bench.step(
        "get_angles in the seed dialect",
        &frame(cmd::GET_ANGLES, &[]),
        50,
        0,
    );
    bench.step("to pymycobot's dialect", &frame(cmd::DIALECT, &[1]), 1, 0);
    // Garbage: 400 bytes rich in frame starts, then a request that must still be answered.
    let mut noise = [0u8; 400];
    let mut seed = 0x2545_F491_4F6C_DD1Du64;
    for b in &mut noise {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        *b = match seed % 5 {
            0 => 0xFE,
            1 => 0xFA,
            _ => (seed >> 24) as u8,
        };
    }
    for chunk in noise.chunks(100) {
        bench.host.send(chunk);
    }
    bench.step(
        "garbage, then get_angles",
        &frame(cmd::GET_ANGLES, &[]),
        1,
        100_000,
    );

    board_log!("clock: {} cycles in {} us", clock_cycles, clock_us);
    board_log!("basic-steps: done");
    loop {
        core::hint::spin_loop();
    }
}

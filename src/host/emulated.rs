//! The virtual robot's bus and servos serving boards that run on an emulated chip: each
//! board's UARTs are sockets (QEMU's `-serial tcp:ADDR,server=on`), this side connects.
//!
//! * A board's bus UART (UART1): what it sends goes on the simulated wire in whole frames, what
//!   the other stations send comes back to it ([`crate::sim::external`] says why not its own
//!   echo).
//! * The front board's host UART (UART0): the pseudo-terminal's bytes go to it, its bytes to
//!   the pseudo-terminal, as the real USB serial would.
//!
//! [`EmulatedBoards`] is a [`RealtimeRobot`]: the same real-time loop and pseudo-terminal serve
//! it, and every socket wakes the loop as soon as it has bytes.

use std::io::{self, ErrorKind, Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::os::fd::{AsFd, BorrowedFd};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use crate::sim::external::{BoardId, EmulatedArm};
use crate::sim::{BusByte, StationId};

use super::realtime::RealtimeRobot;

/// How long [`Chardev::connect`] keeps trying while the emulator starts.
pub const CONNECT_TIMEOUT: Duration = Duration::from_secs(20);

/// How long one attempt to connect may take, and the pause between two: short, so a stop
/// (Ctrl-C while the emulator starts) is seen within a fifth of a second. The emulator's
/// sockets are on this machine, where a connection is answered at once.
const CONNECT_ATTEMPT: Duration = Duration::from_millis(100);

/// One emulated UART, reached through its socket (non-blocking).
#[derive(Debug)]
pub struct Chardev {
    name: &'static str,
    stream: TcpStream,
    /// Bytes the socket did not take yet.
    unsent: Vec<u8>,
    closed: bool,
}

impl Chardev {
    /// Connects to the emulator's socket at `addr`, trying again until `timeout` passes; gives
    /// up (`ErrorKind::Interrupted`) as soon as `stop` is set.
    pub fn connect(
        name: &'static str,
        addr: SocketAddr,
        timeout: Duration,
        stop: &AtomicBool,
    ) -> io::Result<Self> {
        let deadline = Instant::now() + timeout;
        let stream = loop {
            if stop.load(Ordering::Relaxed) {
                return Err(io::Error::new(
                    ErrorKind::Interrupted,
                    format!("stopped while waiting for the {name} at {addr}"),
                ));
            }
            match TcpStream::connect_timeout(&addr, CONNECT_ATTEMPT) {
                Ok(stream) => break stream,
                Err(e) if Instant::now() >= deadline => {
                    return Err(io::Error::new(e.kind(), format!("{name} at {addr}: {e}")));
                }
                Err(_) => std::thread::sleep(CONNECT_ATTEMPT),
            }
        };
        stream.set_nodelay(true)?;
        stream.set_nonblocking(true)?;
        Ok(Self {
            name,
            stream,
            unsent: Vec::new(),
            closed: false,
        })
    }

    /// Appends to `out` every byte that has arrived.
    fn read_into(&mut self, out: &mut Vec<u8>) {
        let mut chunk = [0u8; 1024];
        while !self.closed {
            match self.stream.read(&mut chunk) {
                Ok(0) => self.close("closed by the emulator"),
                Ok(n) => out.extend_from_slice(chunk.get(..n).unwrap_or_default()),
                Err(e) if e.kind() == ErrorKind::WouldBlock => break,
                Err(e) if e.kind() == ErrorKind::Interrupted => {}
                Err(e) => self.close(&e.to_string()),
            }
        }
    }

    /// Sends `bytes` (and what waited before them) as far as the socket takes them now.
    fn send(&mut self, bytes: &[u8]) {
        self.unsent.extend_from_slice(bytes);
        while !self.closed && !self.unsent.is_empty() {
            match self.stream.write(&self.unsent) {
                Ok(n) => drop(self.unsent.drain(..n)),
                Err(e) if e.kind() == ErrorKind::WouldBlock => break,
                Err(e) if e.kind() == ErrorKind::Interrupted => {}
                Err(e) => self.close(&e.to_string()),
            }
        }
    }

    fn close(&mut self, why: &str) {
        if !self.closed {
            eprintln!("open-mycobot: the emulated {} is gone ({why})", self.name);
            self.closed = true;
            self.unsent.clear();
        }
    }
}

/// The environment variable that names a file for [`BusTrace`]'s lines.
pub const BUS_TRACE_ENV: &str = "OPEN_MYCOBOT_BUS_TRACE";

/// A record of the emulated boards' traffic, for finding where time goes (docs/boards.md,
/// "Emulated boards"): every chunk read from or written to a board's socket, stamped with the
/// wall clock and virtual time, and every frame on the simulated wire with its sender and its
/// start and end in virtual time. Off unless [`BUS_TRACE_ENV`] names a file.
///
/// Lines: `W<wall us> V<virtual us> <socket> <in|out> <hex>` for a socket's chunk,
/// `V<start us>-<end us> wire <station> <hex>` for a frame (bytes of one sender less than
/// 100 us apart), with ` GARBLED` when a byte of it collided.
#[derive(Debug)]
struct BusTrace {
    out: std::io::BufWriter<std::fs::File>,
    started: Instant,
    /// The frame on the wire being gathered: sender, start, end of its last byte, bytes.
    frame: Option<(StationId, u64, u64, Vec<u8>, bool)>,
}

impl BusTrace {
    fn from_env() -> Option<Self> {
        let path = std::env::var_os(BUS_TRACE_ENV)?;
        match std::fs::File::create(&path) {
            Ok(file) => Some(Self {
                out: std::io::BufWriter::new(file),
                started: Instant::now(),
                frame: None,
            }),
            Err(e) => {
                eprintln!(
                    "open-mycobot: no bus trace ({}: {e})",
                    path.to_string_lossy()
                );
                None
            }
        }
    }

    fn chunk(&mut self, virtual_us: u64, socket: &str, dir: &str, bytes: &[u8]) {
        if !bytes.is_empty() {
            let wall = self.started.elapsed().as_micros();
            let _ = writeln!(
                self.out,
                "W{wall} V{virtual_us} {socket} {dir} {}",
                hex(bytes)
            );
        }
    }

    fn wire(&mut self, bytes: &[BusByte], names: &dyn Fn(StationId) -> String) {
        for b in bytes {
            match &mut self.frame {
                Some((from, _, end, frame, garbled))
                    if *from == b.from && b.start_ns.saturating_sub(*end) < 100_000 =>
                {
                    *end = b.end_ns;
                    frame.push(b.byte);
                    *garbled |= b.garbled;
                }
                _ => {
                    self.flush_frame(names);
                    self.frame = Some((b.from, b.start_ns, b.end_ns, vec![b.byte], b.garbled));
                }
            }
        }
    }

    fn flush_frame(&mut self, names: &dyn Fn(StationId) -> String) {
        if let Some((from, start, end, frame, garbled)) = self.frame.take() {
            let _ = writeln!(
                self.out,
                "V{}-{} wire {} {}{}",
                start / 1_000,
                end / 1_000,
                names(from),
                hex(&frame),
                if garbled { " GARBLED" } else { "" }
            );
        }
    }
}

impl Drop for BusTrace {
    fn drop(&mut self) {
        let _ = self.out.flush();
    }
}

fn hex(bytes: &[u8]) -> String {
    bytes
        .iter()
        .map(|b| format!("{b:02X}"))
        .collect::<Vec<_>>()
        .join(" ")
}

/// The simulated bus and servos with emulated boards on it, served in real time. See the
/// [module doc](self).
#[derive(Debug)]
pub struct EmulatedBoards {
    arm: EmulatedArm,
    buses: Vec<(BoardId, Chardev)>,
    front: Chardev,
    scratch: Vec<u8>,
    trace: Option<BusTrace>,
}

impl EmulatedBoards {
    /// `arm` with a board attached for each bus socket (with the silence its frames wait for
    /// on the wire, [`EmulatedArm::attach_board`]), and the front board's host UART.
    pub fn new(mut arm: EmulatedArm, buses: Vec<(Chardev, u64)>, front: Chardev) -> Self {
        let buses = buses
            .into_iter()
            .map(|(chardev, quiet_us)| (arm.attach_board(quiet_us), chardev))
            .collect();
        let trace = BusTrace::from_env();
        arm.set_tracing(trace.is_some());
        Self {
            arm,
            buses,
            front,
            scratch: Vec::new(),
            trace,
        }
    }

    /// Writes what went on the wire since the last call to the trace, if there is one.
    fn trace_wire(&mut self) {
        let Some(trace) = &mut self.trace else {
            return;
        };
        let bytes = self.arm.take_trace();
        let boards: Vec<(StationId, &str)> = self
            .buses
            .iter()
            .filter_map(|(board, chardev)| Some((self.arm.station(*board)?, chardev.name)))
            .collect();
        let names = |station: StationId| {
            boards.iter().find(|(s, _)| *s == station).map_or_else(
                || format!("servo-station-{}", station.index()),
                |(_, name)| name.replace(' ', "-"),
            )
        };
        trace.wire(&bytes, &names);
    }
}

impl RealtimeRobot for EmulatedBoards {
    fn now_us(&self) -> u64 {
        self.arm.now_us()
    }

    fn host_write(&mut self, bytes: &[u8]) {
        if let Some(trace) = &mut self.trace {
            trace.chunk(self.arm.now_us(), self.front.name, "out", bytes);
        }
        self.front.send(bytes);
    }

    fn host_read(&mut self, out: &mut Vec<u8>) {
        let from = out.len();
        self.front.read_into(out);
        if let Some(trace) = &mut self.trace {
            let bytes = out.get(from..).unwrap_or_default();
            trace.chunk(self.arm.now_us(), self.front.name, "in", bytes);
        }
    }

    fn run_until(&mut self, t_us: u64) {
        for (board, chardev) in &mut self.buses {
            self.scratch.clear();
            chardev.read_into(&mut self.scratch);
            if let Some(trace) = &mut self.trace {
                trace.chunk(t_us, chardev.name, "in", &self.scratch);
            }
            self.arm.board_sent(*board, t_us, &self.scratch);
        }
        self.arm.run_until(t_us);
        self.trace_wire();
        for (board, chardev) in &mut self.buses {
            self.scratch.clear();
            self.arm.board_received(*board, &mut self.scratch);
            if let Some(trace) = &mut self.trace {
                trace.chunk(t_us, chardev.name, "out", &self.scratch);
            }
            chardev.send(&self.scratch);
        }
    }

    fn wake_fds(&self) -> Vec<BorrowedFd<'_>> {
        self.buses
            .iter()
            .map(|(_, chardev)| chardev)
            .chain(std::iter::once(&self.front))
            .filter(|chardev| !chardev.closed)
            .map(|chardev| chardev.stream.as_fd())
            .collect()
    }

    fn busy(&self) -> bool {
        self.arm.busy()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::net::TcpListener;

    /// An emulated Atom that asks servo 1 for its position: the frame goes on the wire whole,
    /// and the Atom's socket gets the servo's answer.
    #[test]
    fn a_board_on_a_socket_reads_a_servo() {
        let bus_end = TcpListener::bind("127.0.0.1:0").unwrap();
        let front_end = TcpListener::bind("127.0.0.1:0").unwrap();
        let bus = Chardev::connect(
            "Atom's bus UART",
            bus_end.local_addr().unwrap(),
            CONNECT_TIMEOUT,
            &AtomicBool::new(false),
        );
        let front = Chardev::connect(
            "Atom's host UART",
            front_end.local_addr().unwrap(),
            CONNECT_TIMEOUT,
            &AtomicBool::new(false),
        );
        let (mut board, _) = bus_end.accept().unwrap();
        let _front_peer = front_end.accept().unwrap();
        let mut boards = EmulatedBoards::new(
            EmulatedArm::new(1, 2048),
            vec![(bus.unwrap(), 0)],
            front.unwrap(),
        );
        let read = [0xFF, 0xFF, 0x01, 0x04, 0x02, 0x38, 0x02, 0xBE];
        board.write_all(&read).unwrap();
        let mut heard = Vec::new();
        let mut t = 0;
        while heard.len() < 8 {
            t += 100;
            boards.run_until(t);
            let mut chunk = [0u8; 64];
            board.set_nonblocking(true).unwrap();
            if let Ok(n) = board.read(&mut chunk) {
                heard.extend_from_slice(&chunk[..n]);
            }
            assert!(t < 1_000_000, "no answer: {heard:02X?}");
        }
        assert_eq!(heard, [0xFF, 0xFF, 0x01, 0x04, 0x00, 0x00, 0x08, 0xF2]);
    }

    /// A stop while the emulator is not up yet ends the wait, long before the timeout.
    #[test]
    fn a_stop_ends_the_wait_for_the_emulator() {
        let nobody = TcpListener::bind("127.0.0.1:0")
            .unwrap()
            .local_addr()
            .unwrap();
        let stop = std::sync::Arc::new(AtomicBool::new(false));
        let signal = std::sync::Arc::clone(&stop);
        std::thread::spawn(move || {
            std::thread::sleep(Duration::from_millis(100));
            signal.store(true, Ordering::Relaxed);
        });
        let started = Instant::now();
        let error =
            Chardev::connect("Atom's bus UART", nobody, CONNECT_TIMEOUT, &stop).unwrap_err();
        assert_eq!(error.kind(), ErrorKind::Interrupted, "{error}");
        assert!(
            started.elapsed() < CONNECT_TIMEOUT / 4,
            "{:?}",
            started.elapsed()
        );
    }
}

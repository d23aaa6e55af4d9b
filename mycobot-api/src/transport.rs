//! Transports for a PC (the `std` feature): the robot's USB serial ([`SerialPort`]), its
//! Wi-Fi server or the virtual robot's TCP port ([`TcpPort`]), either of them ([`HostPort`]),
//! and a clock ([`SystemClock`]), so the same [`MyCobot`] calls drive an arm from a PC.
//!
//! ```no_run
//! use mycobot_api::MyCobot;
//! use mycobot_api::convert::to_deg;
//! use protocol_core::dialect::Dialect;
//!
//! let mut arm = MyCobot::open_serial("/dev/ttyUSB0", Dialect::Pymycobot)?;
//! println!("{:?}", arm.get_angles()?.map(to_deg));
//! let mut wifi = MyCobot::connect_tcp("192.168.4.1:9000", Dialect::Pymycobot)?;
//! wifi.power_on()?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! Reads block only briefly: a port waits at most [`READ_WAIT`] for a byte when it has none
//! buffered (so a call waiting for its reply does not spin a core), reads whatever has come in
//! one system call and hands it out byte by byte. Writes write everything before returning.
//! An I/O error cannot be returned through [`BytePort`]: the port keeps the first one for
//! [`take_error`](SerialPort::take_error), and the call that met it times out.

use std::io::{self, Read, Write};
use std::net::{SocketAddr, TcpStream, ToSocketAddrs};
use std::path::Path;
use std::time::{Duration, Instant};

use protocol_core::dialect::Dialect;
use protocol_core::port::BytePort;

use crate::robot::{Clock, MyCobot};

/// The Basic's (and the Atom's) USB serial speed, 8N1.
pub const BAUD: u32 = 115_200;

/// Longest a read waits for a byte when none is buffered.
pub const READ_WAIT: Duration = Duration::from_millis(1);

/// How long [`TcpPort::connect`] tries each address.
pub const CONNECT_TIMEOUT: Duration = Duration::from_secs(3);

/// Bytes taken from the system in one read.
const READ_CHUNK: usize = 256;

/// Received bytes not yet handed out, and the first I/O error met.
#[derive(Debug)]
struct Inbox {
    buf: [u8; READ_CHUNK],
    next: usize,
    end: usize,
    error: Option<io::Error>,
}

impl Inbox {
    fn new() -> Self {
        Self {
            buf: [0; READ_CHUNK],
            next: 0,
            end: 0,
            error: None,
        }
    }

    /// The next byte: a buffered one, else whatever `read` brings, waiting at most
    /// [`READ_WAIT`]. Time-outs are "nothing there"; other errors are kept.
    fn read_byte(
        &mut self,
        read: impl FnOnce(&mut [u8], Duration) -> io::Result<usize>,
    ) -> Option<u8> {
        if self.next >= self.end {
            self.next = 0;
            self.end = 0;
            match read(&mut self.buf, READ_WAIT) {
                Ok(0) => {
                    self.keep(io::Error::new(
                        io::ErrorKind::ConnectionAborted,
                        "the robot closed the connection",
                    ));
                    return None;
                }
                Ok(n) => self.end = n.min(READ_CHUNK),
                Err(e) if is_nothing_there(&e) => return None,
                Err(e) => {
                    self.keep(e);
                    return None;
                }
            }
        }
        let byte = self.buf.get(self.next).copied();
        self.next += 1;
        byte
    }

    fn keep(&mut self, error: io::Error) {
        if self.error.is_none() {
            self.error = Some(error);
        }
    }
}

/// A read that found nothing before its timeout.
fn is_nothing_there(e: &io::Error) -> bool {
    matches!(
        e.kind(),
        io::ErrorKind::TimedOut | io::ErrorKind::WouldBlock | io::ErrorKind::Interrupted
    )
}

/// A serial port (the robot's USB serial, a pseudo-terminal of the virtual robot) at
/// 115200 baud, 8N1, no flow control.
pub struct SerialPort {
    port: Box<dyn serialport::SerialPort>,
    inbox: Inbox,
}

impl core::fmt::Debug for SerialPort {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("SerialPort")
            .field("name", &self.port.name())
            .finish_non_exhaustive()
    }
}

impl SerialPort {
    /// Opens `path` at [`BAUD`], 8N1. The error names the port: "no such port /dev/x", or
    /// "cannot open /dev/x: " and the system's reason (busy, permission denied).
    pub fn open(path: impl AsRef<Path>) -> io::Result<Self> {
        let path = path.as_ref();
        let name = path.to_string_lossy();
        if !path.exists() {
            return Err(io::Error::new(
                io::ErrorKind::NotFound,
                format!("no such port {name}"),
            ));
        }
        let port = serialport::new(name.as_ref(), BAUD)
            .data_bits(serialport::DataBits::Eight)
            .parity(serialport::Parity::None)
            .stop_bits(serialport::StopBits::One)
            .flow_control(serialport::FlowControl::None)
            .timeout(READ_WAIT)
            .open()
            .map_err(|e| {
                let e = io::Error::from(e);
                io::Error::new(e.kind(), format!("cannot open {name}: {e}"))
            })?;
        Ok(Self::from_port(port))
    }

    /// Wraps a port opened by the caller (its settings as they are; its read timeout is set
    /// as reads need it).
    pub fn from_port(port: Box<dyn serialport::SerialPort>) -> Self {
        Self {
            port,
            inbox: Inbox::new(),
        }
    }

    /// The port, to change its settings.
    pub fn port_mut(&mut self) -> &mut dyn serialport::SerialPort {
        self.port.as_mut()
    }

    /// The first I/O error met since the last call (the calls meeting it timed out).
    pub fn take_error(&mut self) -> Option<io::Error> {
        self.inbox.error.take()
    }
}

impl BytePort for SerialPort {
    fn read_byte(&mut self) -> Option<u8> {
        let port = &mut self.port;
        self.inbox.read_byte(|buf, wait| {
            if port.timeout() != wait {
                port.set_timeout(wait)?;
            }
            port.read(buf)
        })
    }

    /// Writes all of `bytes` and waits until they have left (tcdrain).
    fn write(&mut self, bytes: &[u8]) {
        if let Err(e) = self.port.write_all(bytes).and_then(|()| self.port.flush()) {
            self.inbox.keep(e);
        }
    }

    fn tx_idle(&self) -> bool {
        true
    }
}

/// A TCP connection: the Basic's Wi-Fi server, or the virtual robot's `--tcp` port. Nagle's
/// algorithm is off, so each request leaves at once.
#[derive(Debug)]
pub struct TcpPort {
    stream: TcpStream,
    /// The stream's read timeout.
    read_wait: Duration,
    inbox: Inbox,
}

impl TcpPort {
    /// Connects to `addr` (each address it resolves to in turn, [`CONNECT_TIMEOUT`] each).
    /// The error names the address: "cannot connect to 127.0.0.1:9000: " and the reason.
    pub fn connect(addr: impl ToSocketAddrs + core::fmt::Display) -> io::Result<Self> {
        let context =
            |e: io::Error| io::Error::new(e.kind(), format!("cannot connect to {addr}: {e}"));
        let addrs: Vec<SocketAddr> = addr.to_socket_addrs().map_err(context)?.collect();
        let mut last = io::Error::new(io::ErrorKind::NotFound, "no address");
        for a in addrs {
            match TcpStream::connect_timeout(&a, CONNECT_TIMEOUT) {
                Ok(stream) => return Self::from_stream(stream).map_err(context),
                Err(e) => last = e,
            }
        }
        Err(context(last))
    }

    /// Wraps a connected stream: sets no delay and a read timeout of [`READ_WAIT`].
    pub fn from_stream(stream: TcpStream) -> io::Result<Self> {
        stream.set_nodelay(true)?;
        stream.set_read_timeout(Some(READ_WAIT))?;
        Ok(Self {
            stream,
            read_wait: READ_WAIT,
            inbox: Inbox::new(),
        })
    }

    /// The stream.
    pub fn stream(&self) -> &TcpStream {
        &self.stream
    }

    /// The first I/O error met since the last call (the calls meeting it timed out); a
    /// connection the robot closed is one.
    pub fn take_error(&mut self) -> Option<io::Error> {
        self.inbox.error.take()
    }
}

impl BytePort for TcpPort {
    fn read_byte(&mut self) -> Option<u8> {
        let (stream, waiting) = (&mut self.stream, &mut self.read_wait);
        self.inbox.read_byte(|buf, wait| {
            if *waiting != wait {
                stream.set_read_timeout(Some(wait))?;
                *waiting = wait;
            }
            stream.read(buf)
        })
    }

    /// Writes all of `bytes` (blocking until the system has taken them).
    fn write(&mut self, bytes: &[u8]) {
        if let Err(e) = self.stream.write_all(bytes) {
            self.inbox.keep(e);
        }
    }

    fn tx_idle(&self) -> bool {
        true
    }
}

/// Either transport, for a program that lets its user choose (the `mycobot` command line).
#[derive(Debug)]
pub enum HostPort {
    /// A serial port.
    Serial(SerialPort),
    /// A TCP connection.
    Tcp(TcpPort),
}

impl HostPort {
    /// The first I/O error met since the last call.
    pub fn take_error(&mut self) -> Option<io::Error> {
        match self {
            Self::Serial(p) => p.take_error(),
            Self::Tcp(p) => p.take_error(),
        }
    }
}

impl BytePort for HostPort {
    fn read_byte(&mut self) -> Option<u8> {
        match self {
            Self::Serial(p) => p.read_byte(),
            Self::Tcp(p) => p.read_byte(),
        }
    }

    fn write(&mut self, bytes: &[u8]) {
        match self {
            Self::Serial(p) => p.write(bytes),
            Self::Tcp(p) => p.write(bytes),
        }
    }

    fn tx_idle(&self) -> bool {
        match self {
            Self::Serial(p) => p.tx_idle(),
            Self::Tcp(p) => p.tx_idle(),
        }
    }
}

/// The system's monotonic clock ([`Instant`]), in microseconds since it was made.
#[derive(Clone, Copy, Debug)]
pub struct SystemClock {
    start: Instant,
}

impl SystemClock {
    /// A clock starting at 0 now.
    pub fn new() -> Self {
        Self {
            start: Instant::now(),
        }
    }
}

impl Default for SystemClock {
    fn default() -> Self {
        Self::new()
    }
}

impl Clock for SystemClock {
    fn now_us(&mut self) -> u64 {
        u64::try_from(self.start.elapsed().as_micros()).unwrap_or(u64::MAX)
    }
}

/// A [`SystemClock`] starting now.
pub fn std_clock() -> SystemClock {
    SystemClock::new()
}

impl MyCobot<SerialPort, SystemClock> {
    /// The robot on the serial port `path` (its USB serial, or the virtual robot's
    /// pseudo-terminal), spoken to in `dialect`. Errors as [`SerialPort::open`]'s.
    pub fn open_serial(path: impl AsRef<Path>, dialect: Dialect) -> io::Result<Self> {
        Ok(Self::new(SerialPort::open(path)?, std_clock(), dialect))
    }
}

impl MyCobot<TcpPort, SystemClock> {
    /// The robot at `addr` (the Basic's Wi-Fi server, the virtual robot's TCP port), spoken to
    /// in `dialect`. Errors as [`TcpPort::connect`]'s.
    pub fn connect_tcp(
        addr: impl ToSocketAddrs + core::fmt::Display,
        dialect: Dialect,
    ) -> io::Result<Self> {
        Ok(Self::new(TcpPort::connect(addr)?, std_clock(), dialect))
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)] // tests: a panic is a failed check

    use std::net::TcpListener;
    use std::thread;

    use super::*;

    /// Reads until `n` bytes have come or `tries` reads found nothing.
    fn read_n(port: &mut impl BytePort, n: usize) -> Vec<u8> {
        let mut got = Vec::new();
        let deadline = Instant::now() + Duration::from_secs(5);
        while got.len() < n && Instant::now() < deadline {
            if let Some(b) = port.read_byte() {
                got.push(b);
            }
        }
        got
    }

    #[test]
    fn a_missing_serial_port_is_named_in_one_line() {
        let e = SerialPort::open("/dev/no-such-mycobot").unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::NotFound);
        assert_eq!(e.to_string(), "no such port /dev/no-such-mycobot");
    }

    #[test]
    fn tcp_reads_nothing_without_blocking_then_hands_out_what_came_in_order() {
        let listener = TcpListener::bind("127.0.0.1:0").unwrap();
        let addr = listener.local_addr().unwrap();
        let server = thread::spawn(move || {
            let (mut peer, _) = listener.accept().unwrap();
            let mut request = [0u8; 5];
            peer.read_exact(&mut request).unwrap();
            // More than one read's chunk, so the buffer refills.
            let reply: Vec<u8> = (0..=255u8).chain(0..=99).collect();
            peer.write_all(&reply).unwrap();
            request
        });
        let mut port = TcpPort::connect(addr.to_string()).unwrap();
        assert_eq!(port.read_byte(), None);
        port.write(&[0xFE, 0xFE, 0x02, 0x12, 0xFA]);
        assert!(port.tx_idle());
        let got = read_n(&mut port, 356);
        let want: Vec<u8> = (0..=255u8).chain(0..=99).collect();
        assert_eq!(got, want);
        assert_eq!(server.join().unwrap(), [0xFE, 0xFE, 0x02, 0x12, 0xFA]);
        // The server is gone: the connection's end is kept as the error.
        let deadline = Instant::now() + Duration::from_secs(5);
        while port.inbox.error.is_none() && Instant::now() < deadline {
            assert_eq!(port.read_byte(), None);
        }
        let e = port
            .take_error()
            .expect("the closed connection is reported");
        assert_eq!(e.kind(), io::ErrorKind::ConnectionAborted);
    }

    #[test]
    fn a_reply_paused_inside_its_frame_still_comes_through() {
        let listener = TcpListener::bind("127.0.0.1:0").unwrap();
        let addr = listener.local_addr().unwrap();
        let server = thread::spawn(move || {
            let (mut peer, _) = listener.accept().unwrap();
            let mut request = [0u8; 5];
            peer.read_exact(&mut request).unwrap();
            // Is powered on: yes, with a pause five times the serial line's frame gap (half the
            // reply gap, REPLY_FRAME_GAP_US) after its fourth byte.
            peer.write_all(&[0xFE, 0xFE, 0x03, 0x12]).unwrap();
            thread::sleep(Duration::from_millis(10));
            peer.write_all(&[0x01, 0xFA]).unwrap();
            request
        });
        let mut arm = MyCobot::connect_tcp(addr, Dialect::Pymycobot).unwrap();
        assert_eq!(arm.is_powered_on(), Ok(true));
        assert_eq!(server.join().unwrap(), [0xFE, 0xFE, 0x02, 0x12, 0xFA]);
    }

    #[test]
    fn a_refused_tcp_connection_names_the_address() {
        // A port just freed: nothing listens there.
        let addr = TcpListener::bind("127.0.0.1:0")
            .unwrap()
            .local_addr()
            .unwrap();
        let e = TcpPort::connect(addr.to_string()).unwrap_err();
        assert!(
            e.to_string()
                .starts_with(&format!("cannot connect to {addr}: ")),
            "{e}"
        );
    }

    #[test]
    fn serial_reads_a_pseudo_terminal_pair() {
        let (mut master, slave) = serialport::TTYPort::pair().unwrap();
        let mut slave: Box<dyn serialport::SerialPort> = Box::new(slave);
        slave.set_timeout(READ_WAIT).unwrap();
        let mut port = SerialPort::from_port(slave);
        assert_eq!(port.read_byte(), None);
        master
            .write_all(&[0xFE, 0xFE, 0x03, 0x12, 0x01, 0xFA])
            .unwrap();
        assert_eq!(read_n(&mut port, 6), [0xFE, 0xFE, 0x03, 0x12, 0x01, 0xFA]);
        port.write(&[1, 2, 3]);
        let mut back = [0u8; 3];
        serialport::SerialPort::set_timeout(&mut master, Duration::from_secs(5)).unwrap();
        master.read_exact(&mut back).unwrap();
        assert_eq!(back, [1, 2, 3]);
    }

    #[test]
    fn the_system_clock_counts_up_from_zero() {
        let mut clock = std_clock();
        let a = clock.now_us();
        thread::sleep(Duration::from_millis(2));
        assert!(clock.now_us() >= a + 2000);
    }
}

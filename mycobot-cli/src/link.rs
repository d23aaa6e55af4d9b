//! The robot at the end of the link the user named, and its failures as one line each.

use std::fmt;

use mycobot_api::transport::{HostPort, SerialPort, SystemClock, TcpPort, std_clock};
use mycobot_api::{Error, MyCobot};
use protocol_core::command::ErrorCode;
use protocol_core::dialect::Dialect;

/// Why a command failed: one line for stderr.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Failure(pub String);

impl fmt::Display for Failure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl From<String> for Failure {
    fn from(line: String) -> Self {
        Self(line)
    }
}

/// The arm, over the serial port or TCP connection opened.
pub type Arm = MyCobot<HostPort, SystemClock>;

/// The robot, and how long it is given to answer (for the messages).
pub struct Robot {
    arm: Arm,
    timeout_ms: u64,
}

impl Robot {
    /// Opens the serial port `port` or connects to `tcp` (one of them is given).
    pub fn open(
        port: Option<&str>,
        tcp: Option<&str>,
        dialect: Dialect,
        timeout_ms: u64,
    ) -> Result<Self, Failure> {
        let host_port = match (port, tcp) {
            (Some(path), _) => HostPort::Serial(SerialPort::open(path).map_err(io_failure)?),
            (None, Some(addr)) => HostPort::Tcp(TcpPort::connect(addr).map_err(io_failure)?),
            (None, None) => return Err(Failure("give --port PATH or --tcp HOST:PORT".into())),
        };
        let mut arm = MyCobot::new(host_port, std_clock(), dialect);
        arm.set_reply_timeout_us(timeout_ms.saturating_mul(1000));
        Ok(Self { arm, timeout_ms })
    }

    /// The dialect spoken.
    pub fn dialect(&self) -> Dialect {
        self.arm.dialect()
    }

    /// Runs one call; its error becomes a line naming the reason (the link's own error, if it
    /// broke).
    pub fn call<T>(
        &mut self,
        call: impl FnOnce(&mut Arm) -> Result<T, Error>,
    ) -> Result<T, Failure> {
        call(&mut self.arm).map_err(|e| self.failure(e))
    }

    /// The line for a call's error.
    pub fn failure(&mut self, e: Error) -> Failure {
        if let Some(io) = self.arm.port_mut().take_error() {
            return Failure(io.to_string());
        }
        match e {
            Error::Timeout { cmd } => Failure(format!(
                "no reply in {} s (command {cmd:#04x}): is the robot on, and the --dialect right?",
                self.timeout_ms as f64 / 1000.0
            )),
            other => Failure(other.to_string()),
        }
    }
}

/// An error opening the link, as one line (its text names the port or address).
fn io_failure(e: std::io::Error) -> Failure {
    Failure(e.to_string())
}

/// What an error code means, in the words [`Error`]'s `Display` gives a refusal.
pub fn error_reason(code: ErrorCode) -> String {
    mycobot_api::Reason(code).to_string()
}

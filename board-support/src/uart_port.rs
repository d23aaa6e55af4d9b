//! [`BytePort`] over an esp-hal UART: non-blocking reads from the RX FIFO, writes that wait
//! only for room in the TX FIFO, and no longer than [`write_budget_us`].

use esp_hal::{
    Blocking,
    uart::{Config, Uart},
};
use protocol_core::{BytePort, timing::wire_time_us};

use crate::{
    clock::now_us,
    deadline::{Deadline, wait_until},
};

/// Bytes the UART's transmit FIFO holds (both chips).
const TX_FIFO_BYTES: u32 = 128;
/// Added to a write's wire time before it is abandoned: the loop's own delays (an interrupt,
/// a slow pass of the FIFO check) must not cut a healthy write short.
const WRITE_SLACK_US: u64 = 1_000;

/// Longest a write of `len` bytes at `baud` may wait for room in the TX FIFO: the wire time of a
/// full FIFO ahead of it and of its own bytes, plus [`WRITE_SLACK_US`]. A UART that drains is
/// always done by then (115200 baud: 11.1 ms + 87 us a byte + 1 ms; 1 Mbaud: 1.28 ms + 10 us a
/// byte + 1 ms); one that does not (a stuck transmitter, an emulator whose socket is not read)
/// loses the rest of the write instead of hanging the loop.
pub fn write_budget_us(len: usize, baud: u32) -> u64 {
    let bytes = u32::try_from(len)
        .unwrap_or(u32::MAX)
        .saturating_add(TX_FIFO_BYTES);
    wire_time_us(bytes, baud).saturating_add(WRITE_SLACK_US)
}

/// The UART settings of a link: `baud` 8N1, everything else esp-hal's defaults.
pub fn config(baud: u32) -> Config {
    Config::default().with_baudrate(baud)
}

/// A UART as the libraries see it.
pub struct UartPort<'d> {
    uart: Uart<'d, Blocking>,
    baud: u32,
    /// When the last queued byte will have left the wire, in microseconds since boot.
    tx_done_at_us: u64,
}

impl<'d> UartPort<'d> {
    /// Wraps `uart`, which was configured at `baud` (needed to know when a write is on the wire).
    pub fn new(uart: Uart<'d, Blocking>, baud: u32) -> Self {
        Self {
            uart,
            baud,
            tx_done_at_us: 0,
        }
    }
}

impl BytePort for UartPort<'_> {
    fn read_byte(&mut self) -> Option<u8> {
        let mut byte = [0_u8; 1];
        match self.uart.read_buffered(&mut byte) {
            Ok(1) => Some(byte[0]),
            // Nothing received yet, or a line error (overrun, framing, parity) was reported and
            // cleared: the damaged bytes are gone and the decoders resynchronise on what follows.
            _ => None,
        }
    }

    fn write(&mut self, bytes: &[u8]) {
        let started_us = now_us();
        let deadline = Deadline::after(started_us, write_budget_us(bytes.len(), self.baud));
        let mut rest = bytes;
        // `Uart::write` itself spins without a deadline while the FIFO is full, so it is called
        // only when `write_ready` says there is room (nothing else fills the FIFO); in between,
        // the deadline decides. What is not queued by then is dropped: the peer sees a cut
        // frame, as after a line error, and its retry or resynchronisation applies.
        let _ = wait_until(now_us, deadline, || {
            if rest.is_empty() {
                return true;
            }
            if !self.uart.write_ready() {
                return false;
            }
            match self.uart.write(rest) {
                Ok(written) => {
                    rest = rest.get(written..).unwrap_or_default();
                    rest.is_empty()
                }
                // The driver refused: give up on the rest at once.
                Err(_) => true,
            }
        });
        let queued = u32::try_from(bytes.len() - rest.len()).unwrap_or(u32::MAX);
        // The UART shifts bytes out back to back at `baud`, after whatever was already queued.
        self.tx_done_at_us = self.tx_done_at_us.max(started_us) + wire_time_us(queued, self.baud);
    }

    fn tx_idle(&self) -> bool {
        // esp-hal has no public non-blocking "transmitter idle" query, so use the wire time of
        // what was queued, which the baud clock makes exact to within a microsecond.
        now_us() >= self.tx_done_at_us
    }
}

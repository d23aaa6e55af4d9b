//! [`BytePort`] over an esp-hal UART: non-blocking reads from the RX FIFO, writes that wait
//! only for room in the TX FIFO.

use esp_hal::{
    Blocking,
    time::Instant,
    uart::{Config, Uart},
};
use protocol_core::{BytePort, timing::wire_time_us};

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

/// Microseconds since boot.
pub fn now_us() -> u64 {
    Instant::now().duration_since_epoch().as_micros()
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
        let mut rest = bytes;
        // `Uart::write` waits only while the FIFO is full, so this takes at most the wire time
        // of `bytes` beyond one FIFO's worth.
        while !rest.is_empty() {
            match self.uart.write(rest) {
                Ok(written) => rest = rest.get(written..).unwrap_or_default(),
                Err(_) => break,
            }
        }
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

//! The byte link both firmwares are written against.
//!
//! A UART on the boards, a simulated wire or a pseudo-terminal in the virtual robot. Reads never
//! block; writes queue bytes for transmission.

/// A full-duplex or half-duplex byte link (UART, simulated wire, pseudo-terminal).
pub trait BytePort {
    /// Takes the next received byte, if one has arrived. Never blocks.
    fn read_byte(&mut self) -> Option<u8>;

    /// Queues `bytes` for transmission, in order. On a board this waits for room in the
    /// hardware FIFO (bounded by the wire time of `bytes`); a simulated port accepts at once.
    fn write(&mut self, bytes: &[u8]);

    /// True once every byte passed to [`BytePort::write`] has left the transmitter.
    fn tx_idle(&self) -> bool;
}

/// A port with nothing attached: never receives, discards what is written. For a board
/// without a direct host link, or a test that does not care about one side.
#[derive(Clone, Copy, Debug, Default)]
pub struct NullPort;

impl BytePort for NullPort {
    fn read_byte(&mut self) -> Option<u8> {
        None
    }

    fn write(&mut self, _bytes: &[u8]) {}

    fn tx_idle(&self) -> bool {
        true
    }
}

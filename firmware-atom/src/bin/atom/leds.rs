//! The Atom's WS2812 RGB LEDs, driven by one RMT channel: every data bit is one RMT pulse code.

use crate::ws2812::{BITS_PER_LED, dimmed, led_bits};
use board_support::{Deadline, now_us, wait_until};
use esp_hal::{
    Blocking,
    gpio::{Level, interconnect::PeripheralOutput},
    rmt::{Channel, PulseCode, Tx, TxChannelConfig, TxChannelCreator},
};

/// LEDs on the chain: the Atom Matrix has 25 (5x5); an Atom Lite's single LED ignores the rest.
pub const LED_COUNT: usize = 25;
/// RMT tick rate the pulse lengths below are counted in (APB clock, divider 1).
pub const RMT_TICK_MHZ: u32 = 80;

/// One pulse code per data bit, plus the end marker.
const PULSE_COUNT: usize = LED_COUNT * BITS_PER_LED + 1;
/// Longest a colour may take to leave before the update is abandoned, microseconds: the
/// chain's wire time is 0.75 ms (600 bits of 1.25 us) and [`Leds::fill`] polls the channel
/// without a pause meanwhile, so 2 ms is only ever reached by a channel that is stuck (a missed
/// end flag, an RMT fault, an emulator without an RMT).
pub const FILL_DEADLINE_US: u64 = 2_000;

// WS2812 bit timing in 12.5 ns ticks: a 0 is 0.40 us high + 0.85 us low, a 1 is 0.80 us high +
// 0.45 us low (datasheet, +-150 ns).
const ZERO: PulseCode = PulseCode::new(Level::High, 32, Level::Low, 68);
const ONE: PulseCode = PulseCode::new(Level::High, 64, Level::Low, 36);

/// The LED chain.
pub struct Leds<'d> {
    channel: Channel<'d, Blocking, Tx>,
    pulses: [PulseCode; PULSE_COUNT],
}

impl<'d> Leds<'d> {
    /// Drives the chain on `pin` from the RMT channel `creator`; `None` if the RMT refuses the
    /// configuration.
    pub fn new<C>(creator: C, pin: impl PeripheralOutput<'d>) -> Option<Self>
    where
        C: TxChannelCreator<'d, Blocking>,
    {
        let config = TxChannelConfig::default()
            .with_clk_divider(1)
            .with_idle_output_level(Level::Low)
            .with_idle_output(true)
            .with_carrier_modulation(false);
        let channel = creator.configure_tx(&config).ok()?.with_pin(pin);
        Some(Self {
            channel,
            pulses: [PulseCode::end_marker(); PULSE_COUNT],
        })
    }

    /// Shows one colour on every LED, dimmed to a safe level ([`dimmed`]). Waits while the
    /// chain's data leaves (0.75 ms for 25 LEDs), at most [`FILL_DEADLINE_US`]; on an error the
    /// LEDs may show anything until the next fill, which starts the channel afresh.
    pub fn fill(&mut self, red: u8, green: u8, blue: u8) -> Result<(), LedError> {
        let bits = led_bits(dimmed(red), dimmed(green), dimmed(blue));
        let (data, _end_marker) = self.pulses.split_at_mut(PULSE_COUNT - 1);
        for (pulse, bit) in data.iter_mut().zip(bits.cycle()) {
            *pulse = if bit { ONE } else { ZERO };
        }
        let mut transaction = self
            .channel
            .reborrow()
            .transmit(&self.pulses)
            .map_err(|_| LedError::Refused)?;
        // The channel's memory holds a fraction of the chain's pulses: each poll refills it, so
        // the loop polls until the end flag, not in between loop passes.
        let deadline = Deadline::after(now_us(), FILL_DEADLINE_US);
        if wait_until(now_us, deadline, || transaction.poll()).is_err() {
            // Abandoned without esp-hal's drop, which stops the channel but on the ESP32 (no
            // immediate stop) then waits, without a deadline, for the end flag that did not
            // come. Nothing is lost by forgetting it: the transaction holds a reborrow of the
            // channel and no hardware resource, and the next `transmit` resets the channel's
            // memory pointers and starts it again.
            core::mem::forget(transaction);
            return Err(LedError::TimedOut);
        }
        // The end (or error) flag is up: `wait` returns at once with the outcome.
        transaction
            .wait()
            .map(|_channel| ())
            .map_err(|_| LedError::Failed)
    }
}

/// Why a colour did not reach the LEDs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LedError {
    /// The RMT refused to start the transmission.
    Refused,
    /// The RMT reported a transmission error.
    Failed,
    /// The transmission did not end by [`FILL_DEADLINE_US`] and was abandoned.
    TimedOut,
}

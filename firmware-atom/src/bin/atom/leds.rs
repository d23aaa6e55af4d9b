//! The Atom's WS2812 RGB LEDs, driven by one RMT channel: every data bit is one RMT pulse code.

use crate::ws2812::{BITS_PER_LED, dimmed, led_bits};
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

    /// Shows one colour on every LED, dimmed to a safe level ([`dimmed`]). Blocks for the
    /// chain's wire time (0.75 ms for 25 LEDs).
    pub fn fill(&mut self, red: u8, green: u8, blue: u8) {
        let bits = led_bits(dimmed(red), dimmed(green), dimmed(blue));
        let (data, _end_marker) = self.pulses.split_at_mut(PULSE_COUNT - 1);
        for (pulse, bit) in data.iter_mut().zip(bits.cycle()) {
            *pulse = if bit { ONE } else { ZERO };
        }
        // A failed transmission leaves the LEDs as they were; the next fill tries again.
        if let Ok(transaction) = self.channel.reborrow().transmit(&self.pulses) {
            let _ = transaction.wait();
        }
    }
}

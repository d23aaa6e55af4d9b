//! PWM arithmetic for the LEDC: duty resolution per frequency and duty in timer ticks. Pure
//! logic, tested on the host (`cargo test -p firmware-atom --test board_logic`).

/// LEDC low-speed timer clock (APB), in Hz.
pub const LEDC_CLOCK_HZ: u32 = 80_000_000;
/// Widest duty resolution used, in bits (the widest every LEDC version supports).
pub const MAX_DUTY_BITS: u32 = 14;

/// The duty resolution for `freq_hz`: as fine as the clock allows, at most [`MAX_DUTY_BITS`].
/// `None` for 0 Hz (no PWM).
pub fn duty_bits(freq_hz: u16) -> Option<u32> {
    let ticks_per_period = LEDC_CLOCK_HZ.checked_div(u32::from(freq_hz))?;
    // 80 MHz / 65535 Hz is still 1220 ticks, so every u16 frequency gets at least 10 bits.
    Some(ticks_per_period.checked_ilog2()?.min(MAX_DUTY_BITS))
}

/// Frequency of hobby-servo pulses, Hz: one pulse every 20 ms.
// Only the ESP32 drives an accessory servo (its LEDC high-speed group).
#[cfg_attr(not(feature = "esp32"), allow(dead_code))]
pub const SERVO_FREQ_HZ: u16 = 50;
/// Period of hobby-servo pulses, microseconds.
#[cfg_attr(not(feature = "esp32"), allow(dead_code))]
pub const SERVO_PERIOD_US: u32 = 20_000;

/// The duty register value for a `pulse_us`-long pulse every [`SERVO_PERIOD_US`] at `bits`
/// resolution (at most the whole period).
#[cfg_attr(not(feature = "esp32"), allow(dead_code))]
pub fn pulse_ticks(pulse_us: u16, bits: u32) -> u32 {
    (u32::from(pulse_us).min(SERVO_PERIOD_US) << bits.min(MAX_DUTY_BITS)) / SERVO_PERIOD_US
}

/// The duty register value for `duty_0_255` / 255 at `bits` resolution: 0 is always low, 255
/// always high (`1 << bits`).
pub fn duty_ticks(duty_0_255: u8, bits: u32) -> u32 {
    (u32::from(duty_0_255) << bits.min(MAX_DUTY_BITS)) / 255
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slow_pwm_gets_the_finest_resolution() {
        assert_eq!(duty_bits(1), Some(14));
        assert_eq!(duty_bits(50), Some(14));
        assert_eq!(duty_bits(1_000), Some(14));
    }

    #[test]
    fn fast_pwm_trades_resolution_for_frequency() {
        // 80 MHz / 10 kHz = 8000 ticks: 12 bits (4096) fit, 13 (8192) do not.
        assert_eq!(duty_bits(10_000), Some(12));
        assert_eq!(duty_bits(u16::MAX), Some(10));
    }

    #[test]
    fn zero_hertz_is_refused() {
        assert_eq!(duty_bits(0), None);
    }

    #[test]
    fn servo_pulses_are_counted_in_the_20_ms_period() {
        // 1.5 ms of 20 ms at 14 bits: 1228.8 ticks.
        assert_eq!(pulse_ticks(1_500, 14), 1_228);
        assert_eq!(pulse_ticks(1_000, 14), 819);
        assert_eq!(pulse_ticks(u16::MAX, 14), 1 << 14);
    }

    #[test]
    fn duty_spans_off_to_fully_on() {
        assert_eq!(duty_ticks(0, 14), 0);
        assert_eq!(duty_ticks(255, 14), 1 << 14);
        assert_eq!(duty_ticks(255, 10), 1 << 10);
        assert_eq!(duty_ticks(128, 10), 514); // 128 / 255 of 1024
    }
}

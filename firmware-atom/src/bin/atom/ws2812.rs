//! WS2812 data: 24 bits per LED, green then red then blue, most significant bit first. Pure
//! logic, tested on the host (`cargo test -p firmware-atom --test board_logic`).

/// Bits sent per LED.
pub const BITS_PER_LED: usize = 24;
/// Brightest level a colour component is driven at, of 255. M5Stack advises keeping the Atom
/// Matrix at 20 or below: its 25 LEDs at full brightness overheat the panel and draw over 1 A.
pub const MAX_LEVEL: u8 = 20;

/// The level actually driven for a requested colour component (0..255): scaled onto
/// 0..[`MAX_LEVEL`], rounding up so that every lit component stays lit.
pub fn dimmed(level: u8) -> u8 {
    let scaled = (u16::from(level) * u16::from(MAX_LEVEL)).div_ceil(255);
    u8::try_from(scaled).unwrap_or(MAX_LEVEL)
}

/// The bits that make one LED show (`red`, `green`, `blue`), in wire order.
pub fn led_bits(red: u8, green: u8, blue: u8) -> impl Clone + Iterator<Item = bool> {
    let grb = (u32::from(green) << 16) | (u32::from(red) << 8) | u32::from(blue);
    (0..BITS_PER_LED)
        .rev()
        .map(move |bit| grb & (1 << bit) != 0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ones(red: u8, green: u8, blue: u8) -> Vec<usize> {
        led_bits(red, green, blue)
            .enumerate()
            .filter_map(|(i, bit)| bit.then_some(i))
            .collect()
    }

    #[test]
    fn colours_are_dimmed_to_a_safe_level_without_going_dark() {
        assert_eq!(dimmed(0), 0);
        assert_eq!(dimmed(1), 1);
        assert_eq!(dimmed(128), 11);
        assert_eq!(dimmed(255), MAX_LEVEL);
    }

    #[test]
    fn green_goes_first_and_blue_last_msb_first() {
        assert_eq!(led_bits(0, 0, 0).count(), BITS_PER_LED);
        assert_eq!(ones(0, 0x80, 0), [0]);
        assert_eq!(ones(0x80, 0, 0), [8]);
        assert_eq!(ones(0, 0, 0x01), [23]);
        assert_eq!(ones(0xFF, 0, 0), (8..16).collect::<Vec<_>>());
    }
}

//! WS2812 data: 24 bits per LED, green then red then blue, most significant bit first. Pure
//! logic, tested on the host (`cargo test -p firmware-atom --test board_logic`).

/// Bits sent per LED.
pub const BITS_PER_LED: usize = 24;

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
    fn green_goes_first_and_blue_last_msb_first() {
        assert_eq!(led_bits(0, 0, 0).count(), BITS_PER_LED);
        assert_eq!(ones(0, 0x80, 0), [0]);
        assert_eq!(ones(0x80, 0, 0), [8]);
        assert_eq!(ones(0, 0, 0x01), [23]);
        assert_eq!(ones(0xFF, 0, 0), (8..16).collect::<Vec<_>>());
    }
}

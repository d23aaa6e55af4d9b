//! The Atom's board-level inputs and outputs, as one small trait the board layer implements.
//!
//! The library checks pin numbers against [`OUTPUT_PINS`] / [`INPUT_PINS`] before calling the
//! trait, so an implementation only has to drive the hardware; it may still refuse (return
//! `false` / `None`), which the library reports to the host as a failed command.

/// The Atom pins clients may drive as outputs or read (`docs/protocol.md` sections 5 and 18).
pub const OUTPUT_PINS: [u8; 4] = [19, 22, 23, 33];
/// The Atom pins clients may read: the IO pins plus the button on GPIO39 (input only).
pub const INPUT_PINS: [u8; 5] = [19, 22, 23, 33, 39];

/// True if clients may configure `pin` as an output (or PWM).
pub fn is_output_pin(pin: u8) -> bool {
    OUTPUT_PINS.contains(&pin)
}

/// True if `pin` may be put in `mode` (0x60): the user pins in any mode; the button pin (GPIO39,
/// input only and without internal pulls on the ESP32) only as a plain input.
pub fn mode_allowed(pin: u8, mode: PinMode) -> bool {
    match mode {
        PinMode::Input => is_input_pin(pin),
        PinMode::Output | PinMode::InputPullUp => is_output_pin(pin),
    }
}

/// True if clients may read `pin`.
pub fn is_input_pin(pin: u8) -> bool {
    INPUT_PINS.contains(&pin)
}

/// How a user pin is configured (host command 0x60).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PinMode {
    /// Floating input.
    Input,
    /// Push-pull output.
    Output,
    /// Input with the internal pull-up enabled.
    InputPullUp,
}

/// Pins, PWM, the RGB LEDs and the button of the Atom. Implemented by the board layer (GPIO,
/// LEDC, RMT) and by the virtual robot. Every method returns at once or, where the hardware
/// needs time (the LEDs' data, flash), by a deadline: a peripheral that does not answer makes
/// the call fail, never wait for ever (docs/boards.md, "Waits and their bounds").
pub trait AtomIo {
    /// Configures `pin`; `false` if the board refuses.
    fn set_pin_mode(&mut self, pin: u8, mode: PinMode) -> bool;
    /// Drives output `pin` high or low; `false` if the board refuses.
    fn write_pin(&mut self, pin: u8, high: bool) -> bool;
    /// The level of `pin` (true = high); `None` if it cannot be read.
    fn read_pin(&mut self, pin: u8) -> Option<bool>;
    /// Starts PWM on `pin` at `freq_hz` with duty `duty_0_255` / 255; `false` if refused.
    fn set_pwm(&mut self, pin: u8, freq_hz: u16, duty_0_255: u8) -> bool;
    /// Sets every RGB LED of the Atom to one colour (0..255 per channel); `false` if the LEDs
    /// did not take it (none, or their data did not leave by its deadline).
    fn set_rgb(&mut self, red: u8, green: u8, blue: u8) -> bool;
    /// True while the Atom's button (GPIO39, active low) is held down.
    fn button_pressed(&mut self) -> bool;
    /// The flash store of servo parameter backups (0xEA/0xEB); `None` if the board has none.
    fn param_store(&mut self) -> Option<&mut dyn crate::store::ParamStore> {
        None
    }

    /// Sends the accessory hobby servo (on the Atom's Grove port, GPIO26; the Connect-4 kit's
    /// dispenser, [`crate::dispenser`]) a `pulse_us`-long pulse every 20 ms, or no pulses
    /// (`None`: the servo goes limp); `false` if the board has no such output (the default).
    fn set_accessory_servo(&mut self, pulse_us: Option<u16>) -> bool {
        let _ = pulse_us;
        false
    }
}

/// Flash of the parameter backups in [`RecordingIo`]: four 4 KiB pages.
pub type MemParams = crate::store::FlashParams<flash_store::MemFlash<{ 4 * 4096 }>>;

/// What is wired to a user pin outside the Atom, in a simulation ([`RecordingIo::set_wiring`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Wiring {
    /// Nothing: an input reads its internal pull (high with [`PinMode::InputPullUp`]), and low
    /// without one (a floating CMOS input is undefined; the model picks low).
    #[default]
    Open,
    /// A device drives the pin high (`true`) or low; it wins over any pull.
    Driven(bool),
    /// An external pull-up resistor: the pin reads high unless something drives it.
    PullUp,
    /// An external pull-down resistor (a few kohm, stronger than the ESP32's ~45 kohm internal
    /// pull-up): the pin reads low unless something drives it.
    PullDown,
}

/// An [`AtomIo`] that remembers what it was told, for tests and the virtual robot. A user pin
/// reads what it outputs in output mode; as an input it reads what is wired to it
/// ([`Wiring`]): a driving device, else an external pull, else its internal pull-up (mode 2),
/// else low. Parameter backups are kept in flash in RAM, which outlives a reset of the Atom.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RecordingIo {
    /// Mode of each user pin, indexed like [`INPUT_PINS`] (`None`: as after reset, a floating
    /// input).
    pub modes: [Option<PinMode>; 5],
    /// Level each user pin outputs in output mode, indexed like [`INPUT_PINS`].
    pub levels: [bool; 5],
    /// What is wired to each user pin outside the Atom, indexed like [`INPUT_PINS`].
    pub wiring: [Wiring; 5],
    /// Last PWM setting of each output pin (frequency in Hz, duty 0..255), like [`OUTPUT_PINS`].
    pub pwm: [Option<(u16, u8)>; 4],
    /// Last colour set on the LEDs (red, green, blue).
    pub rgb: (u8, u8, u8),
    /// The LEDs take no colour (a stuck or missing LED chain): [`AtomIo::set_rgb`] fails and
    /// [`Self::rgb`] stays.
    pub leds_fail: bool,
    /// Whether the button is held.
    pub button: bool,
    /// Pulse the accessory servo gets every 20 ms, microseconds (`None`: no pulses).
    pub accessory_servo_pulse_us: Option<u16>,
    /// The servo parameter backups' flash.
    pub params: MemParams,
}

impl Default for RecordingIo {
    fn default() -> Self {
        Self {
            modes: Default::default(),
            levels: Default::default(),
            pwm: Default::default(),
            rgb: Default::default(),
            leds_fail: false,
            button: false,
            wiring: Default::default(),
            accessory_servo_pulse_us: None,
            params: MemParams::new(flash_store::MemFlash::new(), 0..4 * 4096),
        }
    }
}

impl RecordingIo {
    /// A device drives user pin `pin` high or low (it then reads that level as an input);
    /// `false` if `pin` is not a user pin.
    pub fn set_input(&mut self, pin: u8, high: bool) -> bool {
        self.set_wiring(pin, Wiring::Driven(high))
    }

    /// Wires `what` to user pin `pin`; `false` if `pin` is not a user pin.
    pub fn set_wiring(&mut self, pin: u8, what: Wiring) -> bool {
        match slot(pin).and_then(|i| self.wiring.get_mut(i)) {
            Some(w) => {
                *w = what;
                true
            }
            None => false,
        }
    }
}

fn slot(pin: u8) -> Option<usize> {
    INPUT_PINS.iter().position(|&p| p == pin)
}

impl AtomIo for RecordingIo {
    fn set_pin_mode(&mut self, pin: u8, mode: PinMode) -> bool {
        if mode == PinMode::Output && !is_output_pin(pin) {
            return false;
        }
        match slot(pin).and_then(|i| self.modes.get_mut(i)) {
            Some(m) => {
                *m = Some(mode);
                true
            }
            None => false,
        }
    }

    /// Like the board, writing a level makes the pin an output.
    fn write_pin(&mut self, pin: u8, high: bool) -> bool {
        if !is_output_pin(pin) {
            return false;
        }
        let Some(i) = slot(pin) else { return false };
        if let (Some(level), Some(mode)) = (self.levels.get_mut(i), self.modes.get_mut(i)) {
            *level = high;
            *mode = Some(PinMode::Output);
            return true;
        }
        false
    }

    fn read_pin(&mut self, pin: u8) -> Option<bool> {
        if pin == 39 {
            return Some(!self.button);
        }
        let i = slot(pin)?;
        let mode = self.modes.get(i).copied().flatten();
        if mode == Some(PinMode::Output) {
            return self.levels.get(i).copied();
        }
        Some(match self.wiring.get(i).copied().unwrap_or_default() {
            Wiring::Driven(high) => high,
            Wiring::PullUp => true,
            Wiring::PullDown => false,
            Wiring::Open => mode == Some(PinMode::InputPullUp),
        })
    }

    fn set_pwm(&mut self, pin: u8, freq_hz: u16, duty_0_255: u8) -> bool {
        match OUTPUT_PINS
            .iter()
            .position(|&p| p == pin)
            .and_then(|i| self.pwm.get_mut(i))
        {
            Some(slot) => {
                *slot = Some((freq_hz, duty_0_255));
                true
            }
            None => false,
        }
    }

    fn set_rgb(&mut self, red: u8, green: u8, blue: u8) -> bool {
        if self.leds_fail {
            return false;
        }
        self.rgb = (red, green, blue);
        true
    }

    fn button_pressed(&mut self) -> bool {
        self.button
    }

    fn param_store(&mut self) -> Option<&mut dyn crate::store::ParamStore> {
        Some(&mut self.params)
    }

    fn set_accessory_servo(&mut self, pulse_us: Option<u16>) -> bool {
        self.accessory_servo_pulse_us = pulse_us;
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_button_pin_is_a_plain_input_and_the_user_pins_take_every_mode() {
        assert!(mode_allowed(39, PinMode::Input));
        assert!(
            !mode_allowed(39, PinMode::InputPullUp),
            "GPIO39 has no internal pull"
        );
        assert!(!mode_allowed(39, PinMode::Output));
        for mode in [PinMode::Input, PinMode::Output, PinMode::InputPullUp] {
            assert!(mode_allowed(22, mode));
            assert!(!mode_allowed(25, mode));
        }
    }

    #[test]
    fn inputs_read_their_pulls_and_what_drives_them() {
        let mut io = RecordingIo::default();
        assert_eq!(io.read_pin(22), Some(false), "floating after reset");
        assert!(io.set_pin_mode(22, PinMode::InputPullUp));
        assert_eq!(io.read_pin(22), Some(true), "internal pull-up");
        assert!(io.set_wiring(22, Wiring::PullDown));
        assert_eq!(
            io.read_pin(22),
            Some(false),
            "a stronger external pull-down"
        );
        assert!(io.set_input(22, true));
        assert_eq!(io.read_pin(22), Some(true), "driven high");
        assert!(io.set_wiring(22, Wiring::Open));
        assert!(io.set_pin_mode(22, PinMode::Input));
        assert_eq!(io.read_pin(22), Some(false), "floating again");
        assert!(io.set_wiring(22, Wiring::PullUp));
        assert_eq!(io.read_pin(22), Some(true), "external pull-up");
        // An output reads what it drives.
        assert!(io.set_pin_mode(22, PinMode::Output));
        assert!(io.write_pin(22, false));
        assert_eq!(io.read_pin(22), Some(false));
        assert!(!io.set_wiring(25, Wiring::PullUp), "not a user pin");
    }
}

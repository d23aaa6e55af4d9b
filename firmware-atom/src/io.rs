//! The Atom's board-level inputs and outputs, as one small trait the board layer implements.
//!
//! The library checks pin numbers against [`OUTPUT_PINS`] / [`INPUT_PINS`] before calling the
//! trait, so an implementation only has to drive the hardware; it may still refuse (return
//! `false` / `None`), which the library reports to the host as a failed command.

/// The Atom pins clients may drive as outputs or read (`protocol.md` section 5, `hardware.md`).
pub const OUTPUT_PINS: [u8; 4] = [19, 22, 23, 33];
/// The Atom pins clients may read: the IO pins plus the button on GPIO39 (input only).
pub const INPUT_PINS: [u8; 5] = [19, 22, 23, 33, 39];

/// True if clients may configure `pin` as an output (or PWM).
pub fn is_output_pin(pin: u8) -> bool {
    OUTPUT_PINS.contains(&pin)
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

impl PinMode {
    /// The mode for a wire byte of command 0x60 (0 in, 1 out, 2 in pull-up).
    pub fn from_wire(mode: u8) -> Option<Self> {
        match mode {
            0 => Some(Self::Input),
            1 => Some(Self::Output),
            2 => Some(Self::InputPullUp),
            _ => None,
        }
    }
}

/// Pins, PWM, the RGB LEDs and the button of the Atom. Implemented by the board layer (GPIO,
/// LEDC, RMT) and by the virtual robot. Every method returns at once.
pub trait AtomIo {
    /// Configures `pin`; `false` if the board refuses.
    fn set_pin_mode(&mut self, pin: u8, mode: PinMode) -> bool;
    /// Drives output `pin` high or low; `false` if the board refuses.
    fn write_pin(&mut self, pin: u8, high: bool) -> bool;
    /// The level of `pin` (true = high); `None` if it cannot be read.
    fn read_pin(&mut self, pin: u8) -> Option<bool>;
    /// Starts PWM on `pin` at `freq_hz` with duty `duty_0_255` / 255; `false` if refused.
    fn set_pwm(&mut self, pin: u8, freq_hz: u16, duty_0_255: u8) -> bool;
    /// Sets every RGB LED of the Atom to one colour (0..255 per channel).
    fn set_rgb(&mut self, red: u8, green: u8, blue: u8);
    /// True while the Atom's button (GPIO39, active low) is held down.
    fn button_pressed(&mut self) -> bool;
    /// The flash store of servo parameter backups (0xEA/0xEB); `None` if the board has none.
    fn param_store(&mut self) -> Option<&mut dyn crate::backup::ParamStore> {
        None
    }
}

/// Flash of the parameter backups in [`RecordingIo`]: four 4 KiB pages.
pub type MemParams = crate::backup::FlashParams<flash_store::MemFlash<{ 4 * 4096 }>>;

/// An [`AtomIo`] that remembers what it was told, for tests and the virtual robot: pins read
/// back what was written (inputs read low unless set with [`RecordingIo::set_input`]), and
/// parameter backups kept in flash in RAM (which outlives a reset of the Atom).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RecordingIo {
    /// Mode of each user pin, indexed like [`INPUT_PINS`].
    pub modes: [Option<PinMode>; 5],
    /// Level of each user pin, indexed like [`INPUT_PINS`].
    pub levels: [bool; 5],
    /// Last PWM setting of each output pin (frequency in Hz, duty 0..255), like [`OUTPUT_PINS`].
    pub pwm: [Option<(u16, u8)>; 4],
    /// Last colour set on the LEDs (red, green, blue).
    pub rgb: (u8, u8, u8),
    /// Whether the button is held.
    pub button: bool,
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
            button: false,
            params: MemParams::new(flash_store::MemFlash::new(), 0..4 * 4096),
        }
    }
}

impl RecordingIo {
    /// Sets the level an input pin reads; `false` if `pin` is not a user pin.
    pub fn set_input(&mut self, pin: u8, high: bool) -> bool {
        match slot(pin).and_then(|i| self.levels.get_mut(i)) {
            Some(level) => {
                *level = high;
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

    fn write_pin(&mut self, pin: u8, high: bool) -> bool {
        is_output_pin(pin) && self.set_input(pin, high)
    }

    fn read_pin(&mut self, pin: u8) -> Option<bool> {
        if pin == 39 {
            return Some(!self.button);
        }
        slot(pin).and_then(|i| self.levels.get(i).copied())
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

    fn set_rgb(&mut self, red: u8, green: u8, blue: u8) {
        self.rgb = (red, green, blue);
    }

    fn button_pressed(&mut self) -> bool {
        self.button
    }

    fn param_store(&mut self) -> Option<&mut dyn crate::backup::ParamStore> {
        Some(&mut self.params)
    }
}

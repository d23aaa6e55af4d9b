//! [`AtomIo`] on the chip: the user pins as GPIO or LEDC PWM, the RGB LEDs, the button, and on
//! the ESP32 the accessory hobby servo on the Grove port (LEDC high-speed group).

use esp_hal::{
    gpio::{DriveMode, Flex, Input, InputConfig, Level, NoPin, OutputSignal, Pull},
    ledc::{
        LowSpeed,
        channel::{self, ChannelHW, ChannelIFace},
        timer::{self, LSClockSource, Timer, TimerIFace, TimerSpeed},
    },
    time::Rate,
};
use esp_storage::FlashStorage;
use firmware_atom::io::{AtomIo, OUTPUT_PINS, PinMode};
use firmware_atom::store::{FlashParams, ParamStore};

use board_support::board_log;

use crate::{
    leds::Leds,
    pwm::{duty_bits, duty_ticks},
};
#[cfg(feature = "esp32")]
use esp_hal::ledc::{HighSpeed, timer::HSClockSource};

/// Protocol number of the button pin, readable like a user input (`firmware_atom::io`).
const BUTTON_PIN: u8 = 39;

/// Where the servo parameter backups live: the `nvs` partition of the default partition table
/// espflash writes (0x9000, 24 KiB, six 4 KiB sectors); the firmware does not use ESP-IDF's NVS.
const PARAMS_FLASH: core::ops::Range<u32> = 0x9000..0xF000;

/// One user pin: its GPIO and the LEDC timer, channel and signal reserved for its PWM.
pub struct UserPin<'d> {
    /// The pin itself.
    pub gpio: Flex<'d>,
    /// The LEDC timer that sets this pin's PWM frequency.
    pub timer: Timer<'d, LowSpeed>,
    /// The LEDC channel that generates this pin's PWM.
    pub channel: channel::Number,
    /// That channel's output signal, routed to the pin while PWM is on.
    pub signal: OutputSignal,
}

/// The accessory hobby servo's pin (GPIO26, the Grove port) and the LEDC high-speed timer that
/// times its 50 Hz pulses, with high-speed channel 0 (no user pin uses the high-speed group).
#[cfg(feature = "esp32")]
pub struct AccessoryServo<'d> {
    /// The pin.
    pub gpio: Flex<'d>,
    /// High-speed timer 0.
    pub timer: Timer<'d, HighSpeed>,
}

#[cfg(feature = "esp32")]
impl AccessoryServo<'_> {
    /// Pulses of `pulse_us` every 20 ms, or none (the pin a floating input again).
    fn set(&mut self, pulse_us: Option<u16>) -> bool {
        let signal = OutputSignal::LEDC_HS_SIG0;
        let Some(pulse_us) = pulse_us else {
            signal.disconnect_from(&self.gpio);
            make_input(&mut self.gpio, Pull::None);
            return true;
        };
        start_pwm(
            &mut self.gpio,
            signal,
            &mut self.timer,
            HSClockSource::APBClk,
            channel::Number::Channel0,
            crate::pwm::SERVO_FREQ_HZ,
            |bits| crate::pwm::pulse_ticks(pulse_us, bits),
        )
    }
}

/// The Atom's board IO.
pub struct BoardIo<'d> {
    /// The user pins, in the order of [`OUTPUT_PINS`].
    user: [UserPin<'d>; 4],
    /// The servo parameter backups (0xEA/0xEB) in the Atom's flash.
    params: FlashParams<FlashStorage<'d>>,
    /// Which user pins currently output PWM.
    pwm_on: [bool; 4],
    leds: Option<Leds<'d>>,
    /// LED updates that failed since boot (logged with `log-uart0`).
    led_failures: u32,
    button: Input<'d>,
    /// The accessory hobby servo (ESP32 only).
    #[cfg(feature = "esp32")]
    accessory: Option<AccessoryServo<'d>>,
}

impl<'d> BoardIo<'d> {
    /// Takes the user pins (ordered like [`OUTPUT_PINS`]), the LEDs (if the RMT could drive
    /// them) and the button. User pins start as floating inputs, as after reset.
    pub fn new(
        mut user: [UserPin<'d>; 4],
        leds: Option<Leds<'d>>,
        button: Input<'d>,
        flash: FlashStorage<'d>,
    ) -> Self {
        for pin in &mut user {
            make_input(&mut pin.gpio, Pull::None);
        }
        Self {
            user,
            params: FlashParams::new(flash, PARAMS_FLASH),
            pwm_on: [false; 4],
            leds,
            led_failures: 0,
            button,
            #[cfg(feature = "esp32")]
            accessory: None,
        }
    }

    /// The same IO with the accessory hobby servo on `servo`; its pin starts as a floating
    /// input (no pulses, the servo limp).
    #[cfg(feature = "esp32")]
    pub fn with_accessory(mut self, mut servo: AccessoryServo<'d>) -> Self {
        make_input(&mut servo.gpio, Pull::None);
        self.accessory = Some(servo);
        self
    }

    /// The user pin with protocol number `pin`, and whether it outputs PWM.
    fn user_pin(&mut self, pin: u8) -> Option<(&mut UserPin<'d>, &mut bool)> {
        let index = OUTPUT_PINS.iter().position(|&p| p == pin)?;
        Some((self.user.get_mut(index)?, self.pwm_on.get_mut(index)?))
    }

    /// Gives `pin` back to the GPIO driver if it was outputting PWM.
    fn stop_pwm(pin: &mut UserPin<'d>, pwm_on: &mut bool) {
        if *pwm_on {
            pin.signal.disconnect_from(&pin.gpio);
            *pwm_on = false;
        }
    }
}

/// Starts PWM on `gpio`: `timer` at `freq_hz` from `clock` with the finest duty resolution the
/// clock allows, LEDC channel `number` at the duty `ticks` gives for that resolution (bits), its
/// `signal` routed to the pin through the GPIO matrix. `false` if the LEDC refuses.
fn start_pwm<'d, S>(
    gpio: &mut Flex<'d>,
    signal: OutputSignal,
    timer: &mut Timer<'d, S>,
    clock: S::ClockSourceType,
    number: channel::Number,
    freq_hz: u16,
    ticks: impl FnOnce(u32) -> u32,
) -> bool
where
    S: TimerSpeed,
    Timer<'d, S>: TimerIFace<S>,
{
    let Some(bits) = duty_bits(freq_hz) else {
        return false;
    };
    let Ok(duty) = timer::config::Duty::try_from(bits) else {
        return false;
    };
    let timer_config = timer::config::Config {
        duty,
        clock_source: clock,
        frequency: Rate::from_hz(u32::from(freq_hz)),
    };
    if timer.configure(timer_config).is_err() {
        return false;
    }
    // The channel's signal is routed to the pin by hand below, so the driver gets no pin.
    let mut pwm = channel::Channel::<S>::new(number, NoPin);
    let channel_config = channel::config::Config {
        timer: &*timer,
        duty_pct: 0,
        drive_mode: DriveMode::PushPull,
    };
    if pwm.configure(channel_config).is_err() {
        return false;
    }
    pwm.set_duty_hw(ticks(bits));
    signal.connect_to(&*gpio);
    gpio.set_output_enable(true);
    true
}

fn make_input(gpio: &mut Flex<'_>, pull: Pull) {
    gpio.set_output_enable(false);
    gpio.apply_input_config(&InputConfig::default().with_pull(pull));
    gpio.set_input_enable(true);
}

impl AtomIo for BoardIo<'_> {
    fn set_pin_mode(&mut self, pin: u8, mode: PinMode) -> bool {
        if pin == BUTTON_PIN {
            // The button's pin is always a plain input (the library allows nothing else).
            return mode == PinMode::Input;
        }
        let Some((user, pwm_on)) = self.user_pin(pin) else {
            return false;
        };
        Self::stop_pwm(user, pwm_on);
        match mode {
            PinMode::Input => make_input(&mut user.gpio, Pull::None),
            PinMode::InputPullUp => make_input(&mut user.gpio, Pull::Up),
            PinMode::Output => {
                user.gpio.set_level(Level::Low);
                user.gpio.set_output_enable(true);
            }
        }
        true
    }

    fn write_pin(&mut self, pin: u8, high: bool) -> bool {
        let Some((user, pwm_on)) = self.user_pin(pin) else {
            return false;
        };
        Self::stop_pwm(user, pwm_on);
        user.gpio.set_level(Level::from(high));
        user.gpio.set_output_enable(true);
        true
    }

    fn read_pin(&mut self, pin: u8) -> Option<bool> {
        if pin == BUTTON_PIN {
            return Some(self.button.is_high());
        }
        let (user, _) = self.user_pin(pin)?;
        // The input buffer is on in every mode (`new`), so an output reads back its level.
        Some(user.gpio.is_high())
    }

    fn set_pwm(&mut self, pin: u8, freq_hz: u16, duty_0_255: u8) -> bool {
        let Some((user, pwm_on)) = self.user_pin(pin) else {
            return false;
        };
        let on = start_pwm(
            &mut user.gpio,
            user.signal,
            &mut user.timer,
            LSClockSource::APBClk,
            user.channel,
            freq_hz,
            |bits| duty_ticks(duty_0_255, bits),
        );
        *pwm_on |= on;
        on
    }

    fn set_rgb(&mut self, red: u8, green: u8, blue: u8) -> bool {
        let Some(leds) = &mut self.leds else {
            return false;
        };
        match leds.fill(red, green, blue) {
            Ok(()) => true,
            Err(error) => {
                self.led_failures = self.led_failures.wrapping_add(1);
                board_log!("LED update {:?} ({} so far)", error, self.led_failures);
                false
            }
        }
    }

    fn button_pressed(&mut self) -> bool {
        self.button.is_low()
    }

    fn param_store(&mut self) -> Option<&mut dyn ParamStore> {
        Some(&mut self.params)
    }

    #[cfg(feature = "esp32")]
    fn set_accessory_servo(&mut self, pulse_us: Option<u16>) -> bool {
        self.accessory.as_mut().is_some_and(|a| a.set(pulse_us))
    }
}

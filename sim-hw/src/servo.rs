//! A simulated Feetech STS servo (`docs/servo-bus.md`): the control table, the instructions, a
//! trapezoidal position motion and the faults a test can inject.
//!
//! The servo listens to every byte of the bus ([`SimServo::poll`]), obeys instructions for its
//! id (or the broadcast id), and queues its status reply to start after its return delay
//! (register 7, in 2 us units) plus [`PROCESSING_NS`]. Its shaft moves in fixed control steps of
//! [`CONTROL_PERIOD_NS`] towards the goal position with the goal speed and acceleration, and the
//! present-state registers (56..70) follow. A goal speed of 0 means full speed; the goal time
//! (register 44) is stored but not used, as the firmware always sends a speed.
//!
//! Positions: the shaft has a raw encoder position; registers report `raw - homing offset`
//! (register 31), so writing 128 to torque enable (calibration) makes the present position 2048
//! without moving anything. While torque is off the shaft stays where it is unless a test moves
//! it by hand ([`SimServo::move_by_hand`] at once, [`SimServo::move_by_hand_over`] smoothly over
//! time, its speed reported as the present speed like the real encoder does), and the goal
//! follows the present position so re-enabling torque holds the arm still.
//!
//! Contact ([`SimServo::add_obstacle`], [`SimServo::push`]): the motion profile gives where the
//! position loop wants the shaft (the setpoint); the shaft is there unless something holds it.
//! A rigid stop keeps the shaft on its side; an external torque deflects a held shaft until the
//! motor's torque balances it, and drives it along once the push is stronger than the torque
//! limit (register 48). A new goal is planned from the setpoint on, whatever holds the shaft
//! (the profile is continuous, as a servo's trajectory generator is). The motor's torque is the position loop's: [`STIFFNESS_PER_P`] x P
//! (register 21) per step between setpoint and shaft, capped at the torque limit. It shows as
//! the present load (register 60, thousandths of the maximum torque; a moving shaft adds
//! [`FREE_MOVING_LOAD`] and its inertia, [`INERTIA_LOAD_AT_MAX_ACCEL`] at full acceleration) and current (69); a load
//! at or above the overload torque (register 36, percent) for the protection time (register 35,
//! 10 ms units) trips the overload protection: status bit 32, and the torque cut to the
//! protective torque (register 34, percent) until torque is switched again (register 40).

use std::collections::VecDeque;

use protocol_core::BytePort;
use protocol_core::listener::{Heard, Listener, ListenerConfig};
use protocol_core::servo::{BROADCAST_ID, Instruction, Packet, fault, reg, to_sign_magnitude};
use protocol_core::timing::{BUS_BAUD, HOST_BAUD, wire_time_ns, wire_time_us};

/// Time a servo takes to decode an instruction before its return delay starts, in ns. With the
/// default return delay of 0 the answer starts 12 us after the instruction's last stop bit, well
/// inside [`protocol_core::timing::SERVO_TURNAROUND_MAX_US`].
pub const PROCESSING_NS: u64 = 12_000;
/// Period of the servo's position control loop, in ns (1 kHz, like the STS firmware).
pub const CONTROL_PERIOD_NS: u64 = 1_000_000;
/// Silence between two answers of one SYNC READ, in ns.
pub const SYNC_READ_SLOT_GAP_NS: u64 = 10_000;
/// Fastest the shaft turns, in steps per second (STS3215 at 12 V, about 270 deg/s). A goal
/// speed of 0 means this.
pub const MAX_SPEED_STEPS_PER_S: f64 = 3_000.0;
/// One unit of the acceleration register, in steps per second squared (Feetech's memory table:
/// "if set to 10, it corresponds to an acceleration and deceleration rate of 1000 steps per
/// second squared"; 8.79 deg/s^2 per unit).
pub const ACCEL_UNIT_STEPS_PER_S2: f64 = 100.0;
/// The fastest the shaft speeds up or slows down, in steps/s^2: the acceleration when the
/// register is 0 ("as fast as possible") and the cap of any register value. 11 400 steps/s^2
/// is 1 000 deg/s^2 (register 114): a stop from 150 deg/s takes 0.15 s and 11 deg. Measured
/// STS3215 models (Rhoban's `bam` and K-Scale's system identification: 0.027-0.033 kg m^2
/// reflected at the output, 2.9 N m stall at 12 V) reach 1 200-3 300 deg/s^2 through the
/// servo's position loop, less with the myCobot's low factory P gain and an arm to carry; this
/// model stays below all of them, so the simulated arm never stops faster than a real one
/// (`docs/motion.md`).
pub const MAX_ACCEL_STEPS_PER_S2: f64 = 11_400.0;
/// Present voltage reported, in 0.1 V (the arm's 12 V supply under load).
pub const SUPPLY_DECIVOLT: u8 = 120;
/// Temperature of a servo at rest, in deg C.
pub const AMBIENT_C: u8 = 32;
/// Temperature an injected overheat reports, in deg C (above the default limit of 70).
pub const OVERHEAT_C: u8 = 80;

/// Torque of the position loop per step of error and unit of the P coefficient (register 21),
/// in thousandths of the maximum torque. Feetech does not publish the scaling; with this one the
/// arm's factory P of 10 gives full torque 25 steps (2.2 deg) from the setpoint, and joint 4's
/// P of 32 at 8 steps, as stiff as a hand feels the real joints.
pub const STIFFNESS_PER_P: f64 = 4.0;
/// Load of a shaft moving freely (friction and the arm's inertia), thousandths of max torque.
pub const FREE_MOVING_LOAD: f64 = 180.0;
/// Load of a shaft holding still with nothing pushing it, thousandths of max torque.
pub const HOLDING_LOAD: f64 = 40.0;
/// Extra load of speeding the arm up or slowing it down at [`MAX_ACCEL_STEPS_PER_S2`],
/// thousandths of max torque (in proportion below it): the inertia the motor must overcome.
pub const INERTIA_LOAD_AT_MAX_ACCEL: f64 = 200.0;
/// EEPROM: torque after the overload protection tripped, percent of max (STS3215: 20).
pub const PROTECTIVE_TORQUE: u8 = 34;
/// EEPROM: how long a load at the overload torque lasts before the protection trips, 10 ms
/// units (STS3215: 200, 2 s).
pub const PROTECTION_TIME: u8 = 35;

/// First RAM address; below it is EEPROM (write-protected by register 55).
const FIRST_RAM_ADDR: u8 = reg::TORQUE_ENABLE;
/// Firmware version and model number reported (STS3215, firmware 3.9).
const FIRMWARE: (u8, u8) = (3, 9);
const MODEL_STS3215: u16 = 777;

/// Faults a test can inject into a servo; several may be active at once.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Faults {
    /// The servo hears nothing and never answers (unplugged, dead, or a broken cable).
    pub no_answer: bool,
    /// The servo obeys but every answer has a wrong checksum.
    pub bad_checksum: bool,
    /// The shaft is blocked: it never reaches the goal, the load is high and the overload bit
    /// is set while torque is on.
    pub stall: bool,
    /// The servo is too hot: high temperature and the overheat bit.
    pub overheat: bool,
    /// Every answer starts this many microseconds later than the servo's return delay says (a
    /// slow servo, or a controller that reads its UART late): past the Atom's deadline from
    /// about 200 us on. A late answer still goes on the wire when its time comes, whether or
    /// not the controller is still waiting for it, and garbles whatever else is on the wire
    /// then.
    pub reply_delay_us: u32,
    /// Of every thousand answers, this many are never sent (lost on the way), spread evenly
    /// and deterministically: at 100 every tenth answer, at 500 every other one.
    pub dropped_per_mille: u16,
}

impl Faults {
    /// A healthy servo.
    pub const NONE: Self = Self {
        no_answer: false,
        bad_checksum: false,
        stall: false,
        overheat: false,
        reply_delay_us: 0,
        dropped_per_mille: 0,
    };
    /// Only [`Faults::no_answer`].
    pub const NO_ANSWER: Self = Self {
        no_answer: true,
        ..Self::NONE
    };
    /// Only [`Faults::bad_checksum`].
    pub const BAD_CHECKSUM: Self = Self {
        bad_checksum: true,
        ..Self::NONE
    };
    /// Only [`Faults::stall`].
    pub const STALL: Self = Self {
        stall: true,
        ..Self::NONE
    };
    /// Only [`Faults::overheat`].
    pub const OVERHEAT: Self = Self {
        overheat: true,
        ..Self::NONE
    };

    /// Only [`Faults::reply_delay_us`]: every answer `delay_us` late.
    pub const fn late_replies(delay_us: u32) -> Self {
        Self {
            reply_delay_us: delay_us,
            ..Self::NONE
        }
    }

    /// Only [`Faults::dropped_per_mille`]: `per_mille` of every thousand answers lost.
    pub const fn dropped_replies(per_mille: u16) -> Self {
        Self {
            dropped_per_mille: per_mille,
            ..Self::NONE
        }
    }
}

/// A hand turning a released shaft: raw positions (steps) over time.
#[derive(Clone, Copy, Debug, PartialEq)]
struct HandMove {
    from: f64,
    to: f64,
    start_ns: u64,
    duration_ns: u64,
}

impl HandMove {
    /// Position (steps), speed (steps/s) and whether the move is over, at `now_ns`.
    fn at(&self, now_ns: u64) -> (f64, f64, bool) {
        let elapsed = now_ns.saturating_sub(self.start_ns);
        if elapsed >= self.duration_ns {
            return (self.to, 0.0, true);
        }
        let duration_s = self.duration_ns as f64 / 1e9;
        let phase = std::f64::consts::PI * elapsed as f64 / self.duration_ns as f64;
        let span = self.to - self.from;
        // libm, not f64::cos/sin: the same bits on every host (see sim-hw's Cargo.toml).
        let position = self.from + span * (1.0 - libm::cos(phase)) / 2.0;
        let velocity = span * std::f64::consts::PI / 2.0 * libm::sin(phase) / duration_s;
        (position, velocity, false)
    }
}

/// A rigid stop in the shaft's way: the shaft stays on one side of `raw_steps`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Stop {
    raw_steps: f64,
    keeps_below: bool,
}

impl Stop {
    /// `position` moved back to this stop's side of it.
    fn limit(&self, position: f64) -> f64 {
        if self.keeps_below {
            position.min(self.raw_steps)
        } else {
            position.max(self.raw_steps)
        }
    }
}

/// Counters of what a servo did, for tests and benchmarks.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ServoStats {
    /// Instruction packets addressed to this servo (or broadcast) that it obeyed.
    pub instructions: u64,
    /// Reads (READ or SYNC READ) that included the present position (register 56).
    pub position_reads: u64,
    /// Status packets it queued for sending.
    pub replies: u64,
    /// Writes of a goal position (WRITE, REG WRITE + ACTION, SYNC WRITE).
    pub goal_writes: u64,
}

/// A gap this long inside a packet means it was cut short; the servo drops the partial packet.
/// Longer than the bus stations' `timing::BUS_PACKET_GAP_US`: in transparent mode a tool's
/// packet reaches the bus byte by byte as it arrives at the Basic at 115200 baud, one byte every
/// 87 us, and the servos must still take it whole.
pub const PACKET_GAP_US: u64 = 100;
const _: () = assert!(PACKET_GAP_US > wire_time_us(1, HOST_BAUD));

/// How a servo hears the bus: servo packets only, cut short by [`PACKET_GAP_US`].
const SERVO_LISTENER: ListenerConfig = ListenerConfig::new()
    .with_frames(false)
    .with_packet_gap_us(PACKET_GAP_US);

/// Finds servo packets in the bytes heard on the bus: protocol-core's timed [`Listener`], fed
/// with the nanosecond times of the simulated wire. Each byte is heard at the instant it ends,
/// so a partial packet followed by a quiet gap is dropped before the next byte (a packet cut
/// short must not swallow the next one). One listener can serve every servo on the bus: they
/// all hear the same bytes.
#[derive(Clone, Debug)]
pub struct PacketListener {
    listener: Listener,
}

impl Default for PacketListener {
    fn default() -> Self {
        Self {
            listener: Listener::new(SERVO_LISTENER),
        }
    }
}

impl PacketListener {
    /// Takes one byte that arrived at `end_ns`; calls `on_packet` with each packet it completes.
    pub fn hear(&mut self, byte: u8, end_ns: u64, mut on_packet: impl FnMut(Packet)) {
        let now_us = end_ns / 1_000;
        let mut on_heard = |heard| {
            if let Heard::Packet(packet) = heard {
                on_packet(packet);
            }
        };
        // The silence before this byte is known exactly: let it pass first.
        self.listener.on_time(now_us, &mut on_heard);
        self.listener.push(now_us, byte, &mut on_heard);
    }
}

/// One simulated STS servo. See the [module doc](self).
#[derive(Clone, Debug)]
pub struct SimServo {
    table: [u8; reg::TABLE_SIZE],
    raw_position_steps: f64,
    /// The shaft's speed (the profile's while nothing holds the shaft), steps/s.
    velocity_steps_per_s: f64,
    /// Where the position loop wants the shaft: the motion profile's position, raw steps.
    setpoint_steps: f64,
    /// The motion profile's speed, steps/s.
    setpoint_velocity: f64,
    /// The motion profile's acceleration at the last control step, steps/s^2.
    setpoint_accel: f64,
    last_control_ns: u64,
    /// Rigid stops in the shaft's way ([`SimServo::add_obstacle`]).
    stops: Vec<Stop>,
    /// External torque on the shaft ([`SimServo::push`]), thousandths of max torque.
    push_permille: f64,
    /// The motor's torque at the last control step, thousandths of max torque, signed.
    effort_permille: f64,
    /// Since when the load is at the overload torque, ns.
    overloaded_since_ns: Option<u64>,
    /// The overload protection tripped (cleared by a torque enable write).
    overload_tripped: bool,
    /// Decoder for [`SimServo::poll`] (standalone use).
    listener: PacketListener,
    /// Status packets waiting for their start time (ns), in order.
    replies: VecDeque<(u64, Vec<u8>)>,
    registered: Option<(u8, Vec<u8>)>,
    faults: Faults,
    /// Answers still to send with a wrong checksum ([`SimServo::corrupt_next_answers`]).
    answers_to_corrupt: u32,
    /// A hand turning the released shaft ([`SimServo::move_by_hand_over`]).
    hand: Option<HandMove>,
    /// Writes still to miss ([`SimServo::lose_next_writes`]).
    writes_to_lose: u32,
    /// Answers still to drop ([`SimServo::drop_next_answers`]).
    answers_to_drop: u32,
    /// Spreads [`Faults::dropped_per_mille`] evenly: thousandths of an answer owed to the loss.
    drop_debt: u32,
    stats: ServoStats,
}

impl SimServo {
    /// A servo with factory settings for `id`, its shaft at encoder position `position`.
    /// The PID is set per joint: id 4 gets 32/32/0, the others 10/0/1 (`docs/servo-bus.md`,
    /// which also gives the seed manual's different values).
    pub fn new(id: u8, position: u16) -> Self {
        let mut servo = Self {
            table: [0; reg::TABLE_SIZE],
            raw_position_steps: f64::from(position.min(4095)),
            velocity_steps_per_s: 0.0,
            setpoint_steps: f64::from(position.min(4095)),
            setpoint_velocity: 0.0,
            setpoint_accel: 0.0,
            last_control_ns: 0,
            stops: Vec::new(),
            push_permille: 0.0,
            effort_permille: 0.0,
            overloaded_since_ns: None,
            overload_tripped: false,
            listener: PacketListener::default(),
            replies: VecDeque::new(),
            registered: None,
            faults: Faults::NONE,
            answers_to_corrupt: 0,
            hand: None,
            writes_to_lose: 0,
            answers_to_drop: 0,
            drop_debt: 0,
            stats: ServoStats::default(),
        };
        servo.factory_reset(id);
        servo
    }

    fn factory_reset(&mut self, id: u8) {
        let mut t = [0u8; reg::TABLE_SIZE];
        let mut set = |addr: u8, bytes: &[u8]| {
            for (i, &b) in bytes.iter().enumerate() {
                if let Some(slot) = t.get_mut(usize::from(addr) + i) {
                    *slot = b;
                }
            }
        };
        set(reg::FIRMWARE_MAJOR, &[FIRMWARE.0, FIRMWARE.1]);
        set(reg::MODEL, &MODEL_STS3215.to_le_bytes());
        set(reg::ID, &[id]);
        set(reg::BAUD_RATE, &[0]);
        set(reg::RETURN_DELAY, &[0]);
        set(reg::STATUS_RETURN_LEVEL, &[1]);
        set(reg::MIN_POSITION, &0u16.to_le_bytes());
        set(reg::MAX_POSITION, &4095u16.to_le_bytes());
        set(reg::MAX_TEMPERATURE, &[70]);
        set(reg::MAX_VOLTAGE, &[140]);
        set(reg::MIN_VOLTAGE, &[40]);
        set(reg::MAX_TORQUE, &1000u16.to_le_bytes());
        set(reg::UNLOADING_CONDITION, &[44]);
        set(reg::LED_ALARM, &[47]);
        let pid: [u8; 3] = if id == 4 { [32, 32, 0] } else { [10, 0, 1] };
        set(reg::P_COEFFICIENT, &pid);
        set(reg::MIN_STARTUP_FORCE, &16u16.to_le_bytes());
        set(reg::CW_DEAD_ZONE, &[1, 1]);
        set(reg::HOMING_OFFSET, &0u16.to_le_bytes());
        set(reg::OPERATING_MODE, &[0]);
        set(PROTECTIVE_TORQUE, &[20]);
        set(PROTECTION_TIME, &[200]);
        set(reg::OVERLOAD_TORQUE, &[80]);
        self.table = t;
        self.reset_ram();
    }

    /// The RAM part of the table as at power-up: torque off, goal = present position, torque
    /// limit = max torque (register 16), EEPROM locked.
    fn reset_ram(&mut self) {
        for addr in FIRST_RAM_ADDR..reg::PRESENT_POSITION {
            self.set_reg(addr, 0);
        }
        self.set_u16(reg::TORQUE_LIMIT, self.reg_u16(reg::MAX_TORQUE));
        self.set_reg(reg::EEPROM_LOCK, 1);
        self.overload_tripped = false;
        self.overloaded_since_ns = None;
        self.hold_where_it_is();
        let present = self.present_position();
        self.set_u16(reg::GOAL_POSITION, present);
        self.update_present_registers();
    }

    /// Switches the servo off and on again (a brown-out under load): the EEPROM part of the
    /// table and the shaft stay, the RAM part is as at power-up (torque off), and whatever it
    /// was receiving or about to answer is lost.
    pub fn power_cycle(&mut self) {
        self.replies.clear();
        self.registered = None;
        self.listener = PacketListener::default();
        self.reset_ram();
    }

    /// The servo's current id (register 5).
    pub fn id(&self) -> u8 {
        self.reg(reg::ID)
    }

    /// One byte of the control table.
    pub fn reg(&self, addr: u8) -> u8 {
        self.table.get(usize::from(addr)).copied().unwrap_or(0)
    }

    /// A little-endian two-byte register (raw, sign-magnitude values undecoded).
    pub fn reg_u16(&self, addr: u8) -> u16 {
        u16::from_le_bytes([self.reg(addr), self.reg(addr.wrapping_add(1))])
    }

    /// Present position in steps (register 56): the shaft minus the homing offset, 0..4095.
    pub fn present_position(&self) -> u16 {
        let raw = self.raw_position_steps.round() as i32;
        (raw - self.homing_offset()).rem_euclid(4096) as u16
    }

    /// Where the shaft really is, in steps with their fraction (the present position register
    /// rounds it): the shaft minus the homing offset, for measuring motion finer than a step.
    pub fn shaft_steps(&self) -> f64 {
        self.raw_position_steps - f64::from(self.homing_offset())
    }

    /// Where the shaft physically is, in steps: unlike every register, independent of the
    /// homing offset (a calibration changes what the servo reports, not where it is).
    pub fn physical_steps(&self) -> f64 {
        self.raw_position_steps
    }

    /// The goal position register, in steps.
    pub fn goal_position(&self) -> u16 {
        self.reg_u16(reg::GOAL_POSITION)
    }

    /// True while the motor holds the shaft (register 40 = 1). With 0 (off) and 2 (damping)
    /// the shaft is free: it stays where it is unless moved by hand.
    pub fn torque_enabled(&self) -> bool {
        self.reg(reg::TORQUE_ENABLE) == 1
    }

    /// True while the shaft is moving or has not reached its goal (register 66).
    pub fn is_moving(&self) -> bool {
        self.reg(reg::MOVING) != 0
    }

    /// Active injected faults.
    pub fn faults(&self) -> Faults {
        self.faults
    }

    /// Replaces the injected faults (take effect at once).
    pub fn set_faults(&mut self, faults: Faults) {
        self.faults = faults;
        if faults.no_answer {
            self.replies.clear();
            self.listener = PacketListener::default();
        }
        self.update_present_registers();
    }

    /// Sends the next `count` answers with a wrong checksum, then healthy ones again: a
    /// transient disturbance of its replies (for a permanent one use [`Faults::bad_checksum`]).
    pub fn corrupt_next_answers(&mut self, count: u32) {
        self.answers_to_corrupt = count;
    }

    /// Never sends its next `count` answers (lost on the way), then answers again: a transient
    /// loss of its replies (for a lasting one use [`Faults::dropped_per_mille`]).
    pub fn drop_next_answers(&mut self, count: u32) {
        self.answers_to_drop = count;
    }

    /// Misses the next `count` write instructions addressed to it (WRITE, REG WRITE, or its part
    /// of a SYNC WRITE), as when a collision garbles them on the wire only where this servo
    /// sits; reads and pings are still obeyed.
    pub fn lose_next_writes(&mut self, count: u32) {
        self.writes_to_lose = count;
    }

    /// What this servo did so far.
    pub fn stats(&self) -> ServoStats {
        self.stats
    }

    /// Turns the shaft by hand to present position `position` (steps), as a user does in free
    /// mode. Works with torque on too (the servo then pulls back towards its goal).
    pub fn move_by_hand(&mut self, position: u16) {
        let raw = f64::from(i32::from(position.min(4095)) + self.homing_offset());
        self.raw_position_steps = self.stops.iter().fold(raw, |p, stop| stop.limit(p));
        self.hold_where_it_is();
        if !self.torque_enabled() {
            self.set_u16(reg::GOAL_POSITION, self.present_position());
        }
        self.update_present_registers();
    }

    /// Starts turning the shaft by hand, from where it is at `now_ns`, to present position
    /// `position` (steps) in `duration_ns`, the way a hand does: speeding up and slowing down
    /// smoothly (half a cosine), the speed peaking at pi/2 times the average. Only a released
    /// shaft follows the hand; switching torque on ends the move where the shaft is.
    pub fn move_by_hand_over(&mut self, position: u16, now_ns: u64, duration_ns: u64) {
        self.advance(now_ns);
        let to = f64::from(i32::from(position.min(4095)) + self.homing_offset());
        self.hand = Some(HandMove {
            from: self.raw_position_steps,
            to,
            start_ns: self.last_control_ns,
            duration_ns: duration_ns.max(CONTROL_PERIOD_NS),
        });
    }

    /// True while a hand turns the shaft ([`SimServo::move_by_hand_over`]).
    pub fn hand_moving(&self) -> bool {
        self.hand.is_some()
    }

    /// Puts a rigid stop (an obstacle) at present position `position` (steps, as register 56
    /// counts them), on the side the shaft is on now (at it: below it): from then on neither the
    /// motor nor a hand takes the shaft past it. Stops add up; [`SimServo::clear_obstacles`]
    /// removes them.
    pub fn add_obstacle(&mut self, position: u16) {
        let raw_steps = f64::from(i32::from(position.min(4095)) + self.homing_offset());
        self.stops.push(Stop {
            raw_steps,
            keeps_below: self.raw_position_steps <= raw_steps,
        });
    }

    /// Removes every stop [`SimServo::add_obstacle`] put in the shaft's way.
    pub fn clear_obstacles(&mut self) {
        self.stops.clear();
    }

    /// Pushes on the shaft with an external torque of `permille` thousandths of the servo's
    /// maximum torque (positive towards higher steps; 0 lets go), from the next control step
    /// on. A held shaft gives way until the motor balances the push, and is driven along while
    /// the push is stronger than the torque limit; a free shaft turns with it.
    pub fn push(&mut self, permille: i16) {
        self.push_permille = f64::from(permille.clamp(-3000, 3000));
    }

    /// Where the position loop wants the shaft (the motion profile's position), in steps as
    /// the registers count them: for measuring how far a servo presses past what stopped it.
    pub fn setpoint_steps(&self) -> f64 {
        self.setpoint_steps - f64::from(self.homing_offset())
    }

    /// True while a stop holds the shaft away from where its position loop wants it.
    pub fn blocked(&self) -> bool {
        self.stops.iter().any(|stop| {
            stop.limit(self.setpoint_steps) != self.setpoint_steps
                && (stop.raw_steps - self.raw_position_steps).abs() < 0.5
        })
    }

    /// The next instant this servo has something to do on the bus (a reply to start), in ns.
    pub fn next_event_ns(&self) -> Option<u64> {
        self.replies.front().map(|(t, _)| *t)
    }

    /// Runs the servo up to `now_ns` on its own: moves the shaft, decodes the bytes it heard on
    /// `port` (call this at every byte end, so each byte is heard at its own time), obeys them,
    /// and queues on `port` the replies due by now. The virtual robot (`open_mycobot::sim::VirtualRobot`) instead decodes
    /// the bus once for all servos with a [`PacketListener`] and calls [`SimServo::receive`] and
    /// [`SimServo::transmit_due`].
    pub fn poll(&mut self, now_ns: u64, port: &mut impl BytePort) {
        let mut listener = std::mem::take(&mut self.listener);
        while let Some(byte) = port.read_byte() {
            listener.hear(byte, now_ns, |packet| self.receive(&packet, now_ns));
        }
        self.listener = listener;
        self.transmit_due(now_ns, port);
    }

    /// Obeys `packet`, heard on the bus at `heard_ns` (when its last byte ended), if it is an
    /// instruction for this servo. A servo with the `no_answer` fault hears nothing.
    pub fn receive(&mut self, packet: &Packet, heard_ns: u64) {
        self.advance(heard_ns);
        if !self.faults.no_answer {
            self.obey(packet, heard_ns);
        }
    }

    /// Moves the shaft up to `now_ns` and queues on `port` the replies due by then.
    pub fn transmit_due(&mut self, now_ns: u64, port: &mut impl BytePort) {
        self.advance(now_ns);
        while let Some((_, bytes)) = self.replies.pop_front_if(|(t, _)| *t <= now_ns) {
            port.write(&bytes);
        }
    }

    /// Moves the shaft in control steps up to `now_ns`.
    pub fn advance(&mut self, now_ns: u64) {
        while self.last_control_ns + CONTROL_PERIOD_NS <= now_ns {
            self.last_control_ns += CONTROL_PERIOD_NS;
            self.control_step(CONTROL_PERIOD_NS as f64 / 1e9);
        }
    }

    fn control_step(&mut self, dt_s: f64) {
        if !self.torque_enabled() {
            self.free_step(dt_s);
        } else if self.faults.stall {
            self.hold_where_it_is();
        } else {
            self.profile_step(dt_s);
            self.shaft_step(dt_s);
        }
        self.update_overload();
        self.update_present_registers();
    }

    /// Free shaft: it goes where a hand or a push takes it, and the goal follows it, so
    /// enabling torque holds it where it is.
    fn free_step(&mut self, dt_s: f64) {
        self.velocity_steps_per_s = 0.0;
        if let Some(hand) = self.hand {
            let (position, velocity, done) = hand.at(self.last_control_ns);
            self.raw_position_steps = position;
            self.velocity_steps_per_s = velocity;
            if done {
                self.hand = None;
            }
        } else if self.push_permille != 0.0 {
            self.velocity_steps_per_s = (self.push_permille / 1000.0 * MAX_SPEED_STEPS_PER_S)
                .clamp(-MAX_SPEED_STEPS_PER_S, MAX_SPEED_STEPS_PER_S);
            self.raw_position_steps += self.velocity_steps_per_s * dt_s;
        }
        let shaft = self.stopped(self.raw_position_steps);
        if shaft != self.raw_position_steps {
            self.raw_position_steps = shaft;
            self.velocity_steps_per_s = 0.0;
        }
        self.setpoint_steps = self.raw_position_steps;
        self.setpoint_velocity = 0.0;
        self.setpoint_accel = 0.0;
        self.effort_permille = 0.0;
        let present = self.present_position();
        self.set_u16(reg::GOAL_POSITION, present);
    }

    /// The motion profile: the setpoint towards the goal with the goal speed and acceleration.
    fn profile_step(&mut self, dt_s: f64) {
        let goal = f64::from(i32::from(self.goal_position()) + self.homing_offset());
        let speed = match self.reg_u16(reg::GOAL_SPEED) & 0x7FFF {
            0 => MAX_SPEED_STEPS_PER_S,
            s => f64::from(s).min(MAX_SPEED_STEPS_PER_S),
        };
        let accel = match self.reg(reg::ACCELERATION) {
            0 => MAX_ACCEL_STEPS_PER_S2,
            a => (f64::from(a) * ACCEL_UNIT_STEPS_PER_S2).min(MAX_ACCEL_STEPS_PER_S2),
        };
        let error = goal - self.setpoint_steps;
        let v = self.setpoint_velocity;
        let before = v;
        // Speed we want now: towards the goal, capped so that we can still stop in time.
        let wanted = error.signum() * speed.min((2.0 * accel * error.abs()).sqrt());
        let dv = (wanted - v).clamp(-accel * dt_s, accel * dt_s);
        let mut v_next = v + dv;
        if error.abs() <= 0.5 && v.abs() <= accel * dt_s {
            v_next = 0.0;
        }
        let step = (v + v_next) / 2.0 * dt_s;
        if step * error >= 0.0 && step.abs() >= error.abs() {
            // Arrives within this step: the position loop holds it there (no overshoot).
            self.setpoint_steps = goal;
            self.setpoint_velocity = 0.0;
        } else {
            self.setpoint_steps += step;
            self.setpoint_velocity = v_next;
        }
        self.setpoint_accel = (self.setpoint_velocity - before) / dt_s;
    }

    /// The shaft under the motor: at the setpoint unless a push deflects it or a stop holds it;
    /// the motor's torque is the position loop's, capped at the torque limit.
    fn shaft_step(&mut self, dt_s: f64) {
        let before = self.raw_position_steps;
        let stiffness = STIFFNESS_PER_P * f64::from(self.reg(reg::P_COEFFICIENT).max(1));
        let limit = self.torque_limit_permille();
        let push = self.push_permille;
        let wanted = if push.abs() <= limit {
            // The shaft gives way until the motor's torque balances the push.
            self.setpoint_steps + push / stiffness
        } else {
            // Stronger than the motor: the push drives the shaft along, against the full torque.
            let speed = (push.abs() - limit) / 1000.0 * MAX_SPEED_STEPS_PER_S;
            let held = self.setpoint_steps + push.signum() * limit / stiffness;
            let driven = before + push.signum() * speed * dt_s;
            if push > 0.0 {
                driven.max(held)
            } else {
                driven.min(held)
            }
        };
        let shaft = self.stopped(wanted);
        self.raw_position_steps = shaft;
        self.effort_permille = (stiffness * (self.setpoint_steps - shaft)).clamp(-limit, limit);
        self.velocity_steps_per_s = if shaft == self.setpoint_steps {
            self.setpoint_velocity
        } else {
            (shaft - before) / dt_s
        };
    }

    /// `position` moved back to the allowed side of every stop.
    fn stopped(&self, position: f64) -> f64 {
        self.stops.iter().fold(position, |p, stop| stop.limit(p))
    }

    /// The torque the motor may give now, thousandths of max: the torque limit (register 48),
    /// or the protective torque (register 34) once the overload protection tripped.
    fn torque_limit_permille(&self) -> f64 {
        let limit = f64::from(self.reg_u16(reg::TORQUE_LIMIT).min(1000));
        if self.overload_tripped {
            limit.min(f64::from(self.reg(PROTECTIVE_TORQUE)) * 10.0)
        } else {
            limit
        }
    }

    /// The present load, thousandths of max torque, without its sign.
    fn load_permille(&self) -> f64 {
        if !self.torque_enabled() {
            return 0.0;
        }
        let base = if self.velocity_steps_per_s.round() != 0.0 {
            FREE_MOVING_LOAD
                + INERTIA_LOAD_AT_MAX_ACCEL
                    * (self.setpoint_accel.abs() / MAX_ACCEL_STEPS_PER_S2).min(1.0)
        } else {
            HOLDING_LOAD
        };
        (base + self.effort_permille.abs()).min(self.torque_limit_permille().max(base))
    }

    /// Trips the overload protection after a load at the overload torque (register 36) that
    /// lasted the protection time (register 35).
    fn update_overload(&mut self) {
        let threshold = f64::from(self.reg(reg::OVERLOAD_TORQUE)) * 10.0;
        if self.torque_enabled() && !self.faults.stall && self.load_permille() >= threshold {
            let since = *self.overloaded_since_ns.get_or_insert(self.last_control_ns);
            let protection_ns = u64::from(self.reg(PROTECTION_TIME)) * 10_000_000;
            if self.last_control_ns.saturating_sub(since) >= protection_ns {
                self.overload_tripped = true;
            }
        } else {
            self.overloaded_since_ns = None;
        }
    }

    /// The shaft and the setpoint at rest where the shaft is.
    fn hold_where_it_is(&mut self) {
        self.velocity_steps_per_s = 0.0;
        self.setpoint_accel = 0.0;
        self.setpoint_steps = self.raw_position_steps;
        self.setpoint_velocity = 0.0;
        self.effort_permille = 0.0;
    }

    fn homing_offset(&self) -> i32 {
        i32::from(protocol_core::servo::sign_magnitude(
            self.reg_u16(reg::HOMING_OFFSET),
            11,
        ))
    }

    fn set_u16(&mut self, addr: u8, value: u16) {
        let [lo, hi] = value.to_le_bytes();
        self.set_reg(addr, lo);
        self.set_reg(addr.wrapping_add(1), hi);
    }

    fn set_reg(&mut self, addr: u8, value: u8) {
        if let Some(slot) = self.table.get_mut(usize::from(addr)) {
            *slot = value;
        }
    }

    fn update_present_registers(&mut self) {
        let torque = self.torque_enabled();
        let stalled = self.faults.stall && torque;
        let goal = self.goal_position();
        let present = self.present_position();
        let speed = self.velocity_steps_per_s.round() as i16;
        let load_permille: i16 = if stalled {
            980
        } else {
            self.load_permille().round() as i16
        };
        let direction = if stalled {
            i16::from(goal >= present) * 2 - 1
        } else if self.effort_permille != 0.0 {
            if self.effort_permille > 0.0 { 1 } else { -1 }
        } else if speed < 0 {
            -1
        } else {
            1
        };
        // The servo moves while its profile runs, even if something holds the shaft (without
        // contact the shaft's speed says it).
        let held = self.setpoint_steps != self.raw_position_steps;
        let profile_running = held && self.setpoint_velocity != 0.0;
        let moving = torque && (speed != 0 || profile_running || goal.abs_diff(present) > 1);
        let mut status = 0;
        if stalled || (self.overload_tripped && torque) {
            status |= fault::OVERLOAD;
        }
        if self.faults.overheat {
            status |= fault::OVERHEAT;
        }
        self.set_u16(reg::PRESENT_POSITION, present);
        self.set_u16(reg::PRESENT_SPEED, to_sign_magnitude(speed, 15));
        self.set_u16(
            reg::PRESENT_LOAD,
            to_sign_magnitude(direction * load_permille, 10),
        );
        self.set_reg(reg::PRESENT_VOLTAGE, SUPPLY_DECIVOLT);
        self.set_reg(
            reg::PRESENT_TEMPERATURE,
            if self.faults.overheat {
                OVERHEAT_C
            } else {
                AMBIENT_C + u8::from(stalled) * 8
            },
        );
        self.set_reg(reg::STATUS, status);
        self.set_reg(reg::MOVING, u8::from(moving));
        // About 6.5 mA per unit; the current follows the load.
        self.set_u16(
            reg::PRESENT_CURRENT,
            to_sign_magnitude(direction * load_permille / 2, 15),
        );
    }

    /// Carries out one packet heard at `now_ns` (its last byte ended then).
    fn obey(&mut self, packet: &Packet, now_ns: u64) {
        let id = self.id();
        let broadcast = packet.id() == BROADCAST_ID;
        if packet.id() != id && !broadcast {
            return;
        }
        let Ok(instr) = Instruction::parse(packet) else {
            return;
        };
        let is_write = match instr {
            Instruction::Write { .. } | Instruction::RegWrite { .. } => true,
            Instruction::SyncWrite { .. } => instr.sync_write_data_for(id).is_some(),
            _ => false,
        };
        if is_write && self.writes_to_lose > 0 {
            self.writes_to_lose -= 1;
            return;
        }
        self.stats.instructions += 1;
        let answers_all = self.reg(reg::STATUS_RETURN_LEVEL) >= 1 && !broadcast;
        match instr {
            Instruction::Ping => self.reply(now_ns, &[], !broadcast),
            Instruction::Read { addr, count } => {
                self.note_read(addr, count);
                let data = self.read_block(addr, count);
                self.reply(now_ns, &data, !broadcast);
            }
            Instruction::Write { addr, data } => {
                self.write_block(addr, data);
                self.reply(now_ns, &[], answers_all);
            }
            Instruction::RegWrite { addr, data } => {
                self.registered = Some((addr, data.to_vec()));
                self.reply(now_ns, &[], answers_all);
            }
            Instruction::Action => {
                if let Some((addr, data)) = self.registered.take() {
                    self.write_block(addr, &data);
                }
                self.reply(now_ns, &[], answers_all);
            }
            Instruction::Reset => {
                self.factory_reset(id);
                self.reply(now_ns, &[], answers_all);
            }
            Instruction::SyncRead { addr, count, ids } => {
                if let Some(slot) = ids.iter().position(|&i| i == id) {
                    self.note_read(addr, count);
                    let data = self.read_block(addr, count);
                    let answer_ns = wire_time_ns(6 + u32::from(count), BUS_BAUD);
                    let delay = slot as u64 * (answer_ns + SYNC_READ_SLOT_GAP_NS);
                    self.reply(now_ns + delay, &data, true);
                }
            }
            Instruction::SyncWrite { addr, .. } => {
                if let Some(data) = instr.sync_write_data_for(id) {
                    self.write_block(addr, data);
                }
            }
        }
    }

    fn note_read(&mut self, addr: u8, count: u8) {
        if (addr..addr.saturating_add(count)).contains(&reg::PRESENT_POSITION) {
            self.stats.position_reads += 1;
        }
    }

    /// Queues a status packet (if `send`), starting after the return delay (and the injected
    /// [`Faults::reply_delay_us`]); an answer the faults drop is never sent.
    fn reply(&mut self, heard_ns: u64, data: &[u8], send: bool) {
        if !send || self.drops_answer() {
            return;
        }
        let err = self.reg(reg::STATUS);
        let Some(packet) = Packet::new(self.id(), err, data) else {
            return;
        };
        let mut bytes = packet.to_bytes().to_vec();
        let corrupt = self.faults.bad_checksum || self.answers_to_corrupt > 0;
        self.answers_to_corrupt = self.answers_to_corrupt.saturating_sub(1);
        if corrupt && let Some(chk) = bytes.last_mut() {
            *chk ^= 0x5A;
        }
        let start = heard_ns
            + PROCESSING_NS
            + u64::from(self.reg(reg::RETURN_DELAY)) * 2_000
            + u64::from(self.faults.reply_delay_us) * 1_000;
        self.replies.push_back((start, bytes));
        self.stats.replies += 1;
    }

    /// Whether the answer about to be queued is lost: one of [`SimServo::drop_next_answers`],
    /// or its share of [`Faults::dropped_per_mille`] (every answer adds its thousandths to a
    /// debt; each whole answer owed is dropped).
    fn drops_answer(&mut self) -> bool {
        if self.answers_to_drop > 0 {
            self.answers_to_drop -= 1;
            return true;
        }
        self.drop_debt += u32::from(self.faults.dropped_per_mille.min(1000));
        if self.drop_debt >= 1000 {
            self.drop_debt -= 1000;
            return true;
        }
        false
    }

    fn read_block(&self, addr: u8, count: u8) -> Vec<u8> {
        (0..count).map(|i| self.reg(addr.wrapping_add(i))).collect()
    }

    fn write_block(&mut self, addr: u8, data: &[u8]) {
        let locked = self.reg(reg::EEPROM_LOCK) != 0;
        let mut goal_written = false;
        for (i, &value) in data.iter().enumerate() {
            let Some(a) = u8::try_from(usize::from(addr) + i)
                .ok()
                .filter(|&a| usize::from(a) < reg::TABLE_SIZE)
            else {
                break;
            };
            match a {
                reg::FIRMWARE_MAJOR..=4 => {}
                reg::PRESENT_POSITION.. => {}
                a if a < FIRST_RAM_ADDR && locked => {}
                reg::TORQUE_ENABLE => self.write_torque(value),
                reg::GOAL_POSITION | 43 => {
                    self.set_reg(a, value);
                    goal_written = true;
                }
                reg::EEPROM_LOCK => self.set_reg(a, u8::from(value != 0)),
                _ => self.set_reg(a, value),
            }
        }
        if goal_written {
            self.stats.goal_writes += 1;
            let min = self.reg_u16(reg::MIN_POSITION);
            let max = self.reg_u16(reg::MAX_POSITION);
            let goal = self.goal_position() & 0x0FFF;
            if min < max {
                self.set_u16(reg::GOAL_POSITION, goal.clamp(min, max));
            } else {
                self.set_u16(reg::GOAL_POSITION, goal);
            }
        }
        self.update_present_registers();
    }

    fn write_torque(&mut self, value: u8) {
        match value {
            128 => {
                // Calibration: the shaft's present position becomes 2048.
                let raw = self.raw_position_steps.round() as i32;
                let offset = (raw - 2048).clamp(-2047, 2047) as i16;
                self.set_u16(reg::HOMING_OFFSET, to_sign_magnitude(offset, 11));
                let present = self.present_position();
                self.set_u16(reg::GOAL_POSITION, present);
            }
            0 | 2 => {
                self.set_reg(reg::TORQUE_ENABLE, value);
                self.overload_tripped = false;
                self.hold_where_it_is();
                let present = self.present_position();
                self.set_u16(reg::GOAL_POSITION, present);
            }
            _ => {
                // The servo holds the shaft: a hand turning it lets go.
                self.hand = None;
                self.overload_tripped = false;
                if !self.torque_enabled() {
                    let present = self.present_position();
                    self.set_u16(reg::GOAL_POSITION, present);
                }
                self.set_reg(reg::TORQUE_ENABLE, 1);
            }
        }
    }
}

impl Default for SimServo {
    fn default() -> Self {
        Self::new(1, 2048)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wire::{Bus, BusByte, StationId};
    use protocol_core::servo::{PacketDecoder, SyncWriteBuilder, sign_magnitude};
    use protocol_core::timing::SERVO_TURNAROUND_MAX_US;

    /// A controller and some servos on one bus, stepped at every byte end and servo event.
    struct Rig {
        bus: Bus,
        now_ns: u64,
        controller: StationId,
        servos: Vec<(StationId, SimServo)>,
    }

    impl Rig {
        /// Time from the end of the controller's request to the start of the answer.
        fn turnaround_ns(&self, trace: &[BusByte]) -> u64 {
            let request_end = trace
                .iter()
                .rfind(|b| b.from == self.controller)
                .unwrap()
                .end_ns;
            let answer_start = trace
                .iter()
                .find(|b| b.from != self.controller)
                .unwrap()
                .start_ns;
            answer_start - request_end
        }

        fn new(ids: &[u8]) -> Self {
            let mut bus = Bus::mycobot(3);
            bus.set_tracing(true);
            let controller = bus.attach(false);
            let servos = ids
                .iter()
                .map(|&id| (bus.attach(false), SimServo::new(id, 2048)))
                .collect();
            Self {
                bus,
                now_ns: 0,
                controller,
                servos,
            }
        }

        fn servo(&mut self, i: usize) -> &mut SimServo {
            &mut self.servos[i].1
        }

        fn run_until(&mut self, t_ns: u64) {
            while self.now_ns < t_ns {
                let next = self
                    .servos
                    .iter()
                    .filter_map(|(_, s)| s.next_event_ns())
                    .chain(self.bus.next_event_ns())
                    .chain([t_ns, self.now_ns + CONTROL_PERIOD_NS])
                    .min()
                    .unwrap()
                    .max(self.now_ns + 1);
                self.now_ns = next;
                self.bus.deliver(next);
                for (station, servo) in &mut self.servos {
                    servo.poll(next, &mut self.bus.port(*station).unwrap());
                }
                self.bus.start_transmissions(next);
            }
        }

        fn run_for_ms(&mut self, ms: u64) {
            self.run_until(self.now_ns + ms * 1_000_000);
        }

        /// Sends `packet`, runs 2 ms, returns the trace since the send.
        fn exchange(&mut self, packet: &Packet) -> Vec<BusByte> {
            self.exchange_bytes(&packet.to_bytes())
        }

        fn exchange_bytes(&mut self, bytes: &[u8]) -> Vec<BusByte> {
            self.bus.take_trace();
            self.bus.port(self.controller).unwrap().write(bytes);
            self.bus.start_transmissions(self.now_ns);
            self.run_for_ms(2);
            self.bus.take_trace()
        }

        /// The servo packets in `trace` sent by anyone but the controller, decoded.
        fn answers(&self, trace: &[BusByte]) -> Vec<Packet> {
            let mut decoder = PacketDecoder::new();
            let mut out = Vec::new();
            let bytes: Vec<u8> = trace
                .iter()
                .filter(|b| b.from != self.controller)
                .map(|b| b.byte)
                .collect();
            decoder.feed(&bytes, |p| out.push(p));
            out
        }

        fn read(&mut self, id: u8, addr: u8, count: u8) -> Option<Packet> {
            let trace = self.exchange(&Instruction::Read { addr, count }.to_packet(id).unwrap());
            self.answers(&trace).into_iter().next()
        }

        fn write(&mut self, id: u8, addr: u8, data: &[u8]) -> Vec<Packet> {
            let trace = self.exchange(&Instruction::Write { addr, data }.to_packet(id).unwrap());
            self.answers(&trace)
        }
    }

    fn move_block(accel: u8, goal: u16, speed: u16) -> Vec<u8> {
        let mut block = vec![accel];
        block.extend_from_slice(&goal.to_le_bytes());
        block.extend_from_slice(&[0, 0]);
        block.extend_from_slice(&speed.to_le_bytes());
        block
    }

    #[test]
    fn a_packet_cut_short_does_not_swallow_the_next_one() {
        let mut listener = PacketListener::default();
        let mut heard = Vec::new();
        let read = Instruction::Read { addr: 56, count: 2 }
            .to_packet(2)
            .unwrap();
        // The start of a long WRITE (LEN 0x40: 68 bytes), then, after a silence, a whole READ
        // (bytes 10 us apart). Without the silence the READ would be taken for the WRITE's
        // parameters.
        let mut t_ns = 0;
        for &b in &[0xFF, 0xFF, 0x01, 0x40, 0x03] {
            t_ns += 10_000;
            listener.hear(b, t_ns, |p| heard.push(p));
        }
        t_ns += PACKET_GAP_US * 1_000;
        for &b in read.to_bytes().iter() {
            t_ns += 10_000;
            listener.hear(b, t_ns, |p| heard.push(p));
        }
        assert_eq!(heard, [read]);
    }

    #[test]
    fn ping_is_answered_within_the_turnaround_budget() {
        let mut rig = Rig::new(&[1]);
        let trace = rig.exchange(&Instruction::Ping.to_packet(1).unwrap());
        let turnaround = rig.turnaround_ns(&trace);
        assert!(turnaround > 0 && turnaround <= SERVO_TURNAROUND_MAX_US * 1_000);
        let answers = rig.answers(&trace);
        assert_eq!(answers.len(), 1);
        assert_eq!((answers[0].id(), answers[0].code()), (1, 0));
        assert!(answers[0].params().is_empty());
    }

    #[test]
    fn return_delay_register_lengthens_the_turnaround() {
        let mut rig = Rig::new(&[1]);
        rig.write(1, reg::RETURN_DELAY, &[50]);
        assert_eq!(rig.servo(0).reg(reg::RETURN_DELAY), 0, "EEPROM is locked");
        rig.write(1, reg::EEPROM_LOCK, &[0]);
        rig.write(1, reg::RETURN_DELAY, &[50]);
        let trace = rig.exchange(&Instruction::Ping.to_packet(1).unwrap());
        assert_eq!(rig.turnaround_ns(&trace), 100_000 + PROCESSING_NS);
    }

    #[test]
    fn factory_table_reads_back() {
        let mut rig = Rig::new(&[4]);
        let eeprom = rig.read(4, 0, 40).unwrap();
        let p = eeprom.params();
        assert_eq!(p.len(), 40);
        assert_eq!(u16::from_le_bytes([p[3], p[4]]), MODEL_STS3215);
        assert_eq!(p[usize::from(reg::ID)], 4);
        assert_eq!(p[usize::from(reg::BAUD_RATE)], 0);
        assert_eq!(u16::from_le_bytes([p[11], p[12]]), 4095);
        assert_eq!(
            &p[21..24],
            &[32, 32, 0],
            "joint 4 has the vendor's stiffer PID"
        );
        let mut other = Rig::new(&[2]);
        assert_eq!(
            &other.read(2, reg::P_COEFFICIENT, 3).unwrap().params(),
            &[10, 0, 1]
        );
        let state = rig.read(4, reg::STATE_BLOCK, reg::STATE_BLOCK_LEN).unwrap();
        assert_eq!(state.u16_at(0), Some(2048));
        assert_eq!(state.params()[6], SUPPLY_DECIVOLT);
        assert_eq!(state.params()[7], AMBIENT_C);
        assert_eq!(state.params()[10], 0, "not moving");
    }

    #[test]
    fn goal_with_speed_and_acceleration_moves_along_a_trapezoid() {
        let mut rig = Rig::new(&[1]);
        rig.write(1, reg::TORQUE_ENABLE, &[1]);
        // 1000 steps at 1000 steps/s with 5000 steps/s^2: 0.2 s ramps, 1.2 s in total.
        let acks = rig.write(1, reg::MOVE_BLOCK, &move_block(50, 3048, 1000));
        assert_eq!(acks.len(), 1, "status return level 1 acknowledges writes");
        rig.run_for_ms(100);
        let early = rig.servo(0).present_position();
        assert!(
            (2048 + 15..2048 + 35).contains(&early),
            "accelerating: {early}"
        );
        rig.run_for_ms(400);
        let state = rig.read(1, reg::STATE_BLOCK, reg::STATE_BLOCK_LEN).unwrap();
        let speed = sign_magnitude(state.u16_at(2).unwrap(), 15);
        assert!(
            (990..=1000).contains(&speed),
            "cruising at the goal speed: {speed}"
        );
        assert_eq!(state.params()[10], 1, "moving flag");
        assert!(
            sign_magnitude(state.u16_at(4).unwrap(), 10) > 0,
            "load while moving"
        );
        rig.run_for_ms(600);
        assert!(rig.servo(0).is_moving());
        assert!(rig.servo(0).present_position() < 3048);
        rig.run_for_ms(150);
        assert_eq!(rig.servo(0).present_position(), 3048);
        assert!(!rig.servo(0).is_moving());
        let state = rig.read(1, reg::STATE_BLOCK, reg::STATE_BLOCK_LEN).unwrap();
        assert_eq!(state.u16_at(2), Some(0));
    }

    #[test]
    fn arrives_exactly_at_the_goal_without_overshoot() {
        for (accel, speed) in [(0, 0), (20, 3000), (5, 400), (254, 500)] {
            let mut rig = Rig::new(&[1]);
            rig.write(1, reg::TORQUE_ENABLE, &[1]);
            rig.write(1, reg::MOVE_BLOCK, &move_block(accel, 2788, speed));
            let mut furthest = 0;
            for _ in 0..3_000 {
                rig.run_for_ms(1);
                furthest = furthest.max(rig.servo(0).present_position());
                if !rig.servo(0).is_moving() {
                    break;
                }
            }
            assert_eq!(furthest, 2788, "accel {accel} speed {speed}");
            assert_eq!(rig.servo(0).present_position(), 2788);
        }
    }

    #[test]
    fn the_shaft_never_brakes_faster_than_a_real_sts3215() {
        for accel in [0u8, 114, 254] {
            let mut rig = Rig::new(&[1]);
            rig.write(1, reg::TORQUE_ENABLE, &[1]);
            // Full speed (1707 steps/s, 150 deg/s) towards a far goal, then a goal right where
            // the shaft is: at 11 400 steps/s^2 it needs 128 steps to stop.
            rig.write(1, reg::MOVE_BLOCK, &move_block(0, 4000, 1707));
            rig.run_for_ms(400);
            let start = rig.servo(0).present_position();
            rig.write(1, reg::MOVE_BLOCK, &move_block(accel, start, 1707));
            let mut furthest = start;
            for _ in 0..400 {
                rig.run_for_ms(1);
                furthest = furthest.max(rig.servo(0).present_position());
            }
            assert!(
                furthest - start >= 120,
                "accel {accel}: stopped {} steps after the goal was set",
                furthest - start
            );
            assert_eq!(rig.servo(0).present_position(), start, "back at its goal");
        }
    }

    #[test]
    fn moves_backwards_too_and_respects_position_limits() {
        let mut rig = Rig::new(&[1]);
        rig.write(1, reg::TORQUE_ENABLE, &[1]);
        rig.write(1, reg::EEPROM_LOCK, &[0]);
        rig.write(1, reg::MIN_POSITION, &1500u16.to_le_bytes());
        rig.write(1, reg::EEPROM_LOCK, &[1]);
        rig.write(1, reg::MOVE_BLOCK, &move_block(0, 100, 0));
        assert_eq!(rig.servo(0).goal_position(), 1500);
        rig.run_for_ms(800);
        assert_eq!(rig.servo(0).present_position(), 1500);
    }

    #[test]
    fn torque_off_holds_nothing_and_hand_moves_stick() {
        let mut rig = Rig::new(&[1]);
        rig.write(1, reg::MOVE_BLOCK, &move_block(0, 3000, 0));
        rig.run_for_ms(300);
        assert_eq!(
            rig.servo(0).present_position(),
            2048,
            "torque is off at power-up"
        );
        rig.servo(0).move_by_hand(1000);
        rig.run_for_ms(10);
        assert_eq!(
            rig.read(1, reg::PRESENT_POSITION, 2).unwrap().u16_at(0),
            Some(1000)
        );
        // Enabling torque holds the arm where the hand left it.
        rig.write(1, reg::TORQUE_ENABLE, &[1]);
        rig.run_for_ms(100);
        assert_eq!(rig.servo(0).present_position(), 1000);
    }

    #[test]
    fn a_hand_turns_a_released_shaft_smoothly_and_its_speed_is_reported() {
        let mut rig = Rig::new(&[1]);
        let now = rig.now_ns;
        rig.servo(0)
            .move_by_hand_over(2048 + 400, now, 1_000_000_000);
        rig.run_for_ms(500);
        // Half way in time is half way in position, at the peak speed of pi/2 x 400 steps/s.
        let position = rig
            .read(1, reg::PRESENT_POSITION, 2)
            .unwrap()
            .u16_at(0)
            .unwrap();
        assert!((i32::from(position) - 2248).abs() <= 3, "{position}");
        let speed = rig
            .read(1, reg::PRESENT_SPEED, 2)
            .unwrap()
            .u16_at(0)
            .unwrap();
        assert!((f64::from(speed) - 628.0).abs() < 10.0, "{speed} steps/s");
        assert!(rig.servo(0).hand_moving());
        rig.run_for_ms(600);
        assert!(!rig.servo(0).hand_moving());
        assert_eq!(rig.servo(0).present_position(), 2448);
        assert_eq!(
            rig.read(1, reg::PRESENT_SPEED, 2).unwrap().u16_at(0),
            Some(0)
        );
        // Torque on: the servo holds, the hand lets go.
        let now = rig.now_ns;
        rig.servo(0).move_by_hand_over(1000, now, 1_000_000_000);
        rig.run_for_ms(100);
        rig.write(1, reg::TORQUE_ENABLE, &[1]);
        let held = rig.servo(0).present_position();
        rig.run_for_ms(1_000);
        assert!(!rig.servo(0).hand_moving());
        assert!(rig.servo(0).present_position().abs_diff(held) <= 2);
    }

    #[test]
    fn a_hand_move_follows_the_same_path_on_every_host() {
        // 41.19 ms into a 2048 -> 2560 turn over a second: here glibc's sin on i686 is one bit
        // off its x86_64 one, and so was the speed when the path used f64::sin. The bits are
        // libm's; a libm upgrade that moves them by an ulp is fine, update them then.
        // (black_box: else the compiler works the path out itself, with its own host's sin.)
        let hand = std::hint::black_box(HandMove {
            from: 2048.0,
            to: 2560.0,
            start_ns: 0,
            duration_ns: 1_000_000_000,
        });
        let (position, speed, over) = hand.at(std::hint::black_box(41_190_000));
        assert!(!over);
        assert_eq!(position.to_bits(), 0x40a0_0447_dd81_1b1f, "{position}");
        assert_eq!(speed.to_bits(), 0x4059_f1ff_9175_5817, "{speed}");
    }

    #[test]
    fn a_power_cycle_keeps_the_eeprom_and_drops_torque() {
        let mut rig = Rig::new(&[1]);
        rig.write(1, reg::EEPROM_LOCK, &[0]);
        rig.write(1, reg::MIN_POSITION, &100u16.to_le_bytes());
        rig.write(1, reg::TORQUE_ENABLE, &[1]);
        rig.write(1, reg::MOVE_BLOCK, &move_block(0, 2500, 0));
        rig.run_for_ms(600);
        rig.servo(0).power_cycle();
        let servo = rig.servo(0);
        assert!(!servo.torque_enabled());
        assert_eq!(servo.reg(reg::EEPROM_LOCK), 1);
        assert_eq!(servo.reg_u16(reg::MIN_POSITION), 100);
        assert_eq!(servo.present_position(), 2500);
        assert_eq!(servo.goal_position(), 2500);
        assert_eq!(servo.reg_u16(reg::TORQUE_LIMIT), 1000);
    }

    #[test]
    fn damping_mode_leaves_the_shaft_free() {
        let mut rig = Rig::new(&[1]);
        rig.write(1, reg::TORQUE_ENABLE, &[2]);
        assert_eq!(rig.servo(0).reg(reg::TORQUE_ENABLE), 2);
        assert!(!rig.servo(0).torque_enabled());
        rig.write(1, reg::MOVE_BLOCK, &move_block(0, 3000, 0));
        rig.run_for_ms(200);
        assert_eq!(rig.servo(0).present_position(), 2048);
    }

    #[test]
    fn torque_128_makes_the_present_position_2048_without_moving() {
        let mut rig = Rig::new(&[1]);
        rig.servo(0).move_by_hand(2500);
        rig.write(1, reg::TORQUE_ENABLE, &[128]);
        assert_eq!(
            rig.read(1, reg::PRESENT_POSITION, 2).unwrap().u16_at(0),
            Some(2048)
        );
        let offset = rig
            .read(1, reg::HOMING_OFFSET, 2)
            .unwrap()
            .u16_at(0)
            .unwrap();
        assert_eq!(sign_magnitude(offset, 11), 452);
        // Goals are in the calibrated frame: 2148 is 100 steps past the new zero.
        rig.write(1, reg::TORQUE_ENABLE, &[1]);
        rig.write(1, reg::MOVE_BLOCK, &move_block(0, 2148, 0));
        rig.run_for_ms(200);
        assert_eq!(rig.servo(0).present_position(), 2148);
    }

    #[test]
    fn eeprom_lock_protects_the_id() {
        let mut rig = Rig::new(&[3]);
        rig.write(3, reg::ID, &[9]);
        assert_eq!(rig.servo(0).id(), 3);
        rig.write(3, reg::EEPROM_LOCK, &[0]);
        rig.write(3, reg::ID, &[9]);
        assert_eq!(rig.servo(0).id(), 9);
        assert!(rig.read(3, reg::ID, 1).is_none());
        assert_eq!(rig.read(9, reg::ID, 1).unwrap().params(), &[9]);
    }

    #[test]
    fn read_only_registers_ignore_writes() {
        let mut rig = Rig::new(&[1]);
        rig.write(1, reg::EEPROM_LOCK, &[0]);
        rig.write(1, reg::MODEL, &[1, 2]);
        rig.write(1, reg::PRESENT_POSITION, &[0, 0]);
        assert_eq!(rig.servo(0).reg_u16(reg::MODEL), MODEL_STS3215);
        assert_eq!(rig.servo(0).present_position(), 2048);
    }

    #[test]
    fn broadcast_and_status_return_level_silence_replies() {
        let mut rig = Rig::new(&[1, 2]);
        assert!(rig.write(BROADCAST_ID, reg::TORQUE_ENABLE, &[1]).is_empty());
        assert!(rig.servo(0).torque_enabled() && rig.servo(1).torque_enabled());
        rig.write(1, reg::EEPROM_LOCK, &[0]);
        rig.write(1, reg::STATUS_RETURN_LEVEL, &[0]);
        assert_eq!(rig.servo(0).reg(reg::STATUS_RETURN_LEVEL), 0);
        assert!(
            rig.write(1, reg::GOAL_POSITION, &2100u16.to_le_bytes())
                .is_empty()
        );
        assert!(
            rig.read(1, reg::GOAL_POSITION, 2).is_some(),
            "READ still answers"
        );
        assert_eq!(
            rig.write(2, reg::GOAL_POSITION, &2100u16.to_le_bytes())
                .len(),
            1
        );
    }

    #[test]
    fn sync_write_moves_each_servo_to_its_own_goal_without_replies() {
        let mut rig = Rig::new(&[1, 2, 3]);
        rig.write(BROADCAST_ID, reg::TORQUE_ENABLE, &[1]);
        let mut sync = SyncWriteBuilder::new(reg::MOVE_BLOCK, reg::MOVE_BLOCK_LEN);
        for (id, goal) in [(1, 1000), (3, 3000)] {
            sync.push(id, &move_block(0, goal, 0)).unwrap();
        }
        let trace = rig.exchange(&sync.to_packet().unwrap());
        assert!(rig.answers(&trace).is_empty());
        rig.run_for_ms(1000);
        let positions: Vec<u16> = (0..3).map(|i| rig.servo(i).present_position()).collect();
        assert_eq!(positions, vec![1000, 2048, 3000]);
    }

    #[test]
    fn sync_read_answers_in_order_without_colliding() {
        let mut rig = Rig::new(&[1, 2, 3]);
        rig.servo(1).move_by_hand(1111);
        let ids = [3, 1, 2];
        let packet = Instruction::SyncRead {
            addr: reg::STATE_BLOCK,
            count: reg::STATE_BLOCK_LEN,
            ids: &ids,
        }
        .to_packet(BROADCAST_ID)
        .unwrap();
        let trace = rig.exchange(&packet);
        assert_eq!(rig.bus.collisions(), 0);
        let answers = rig.answers(&trace);
        let got: Vec<(u8, Option<u16>)> = answers.iter().map(|p| (p.id(), p.u16_at(0))).collect();
        assert_eq!(got, vec![(3, Some(2048)), (1, Some(2048)), (2, Some(1111))]);
    }

    #[test]
    fn reg_write_waits_for_action() {
        let mut rig = Rig::new(&[1]);
        rig.write(1, reg::TORQUE_ENABLE, &[1]);
        let block = move_block(0, 2500, 0);
        let held = Instruction::RegWrite {
            addr: reg::MOVE_BLOCK,
            data: &block,
        };
        rig.exchange(&held.to_packet(1).unwrap());
        rig.run_for_ms(100);
        assert_eq!(rig.servo(0).present_position(), 2048);
        rig.exchange(&Instruction::Action.to_packet(BROADCAST_ID).unwrap());
        rig.run_for_ms(600);
        assert_eq!(rig.servo(0).present_position(), 2500);
        assert_eq!(rig.servo(0).stats().goal_writes, 1);
    }

    #[test]
    fn silent_servo_does_not_answer_but_the_others_do() {
        let mut rig = Rig::new(&[1, 2]);
        rig.servo(0).set_faults(Faults::NO_ANSWER);
        assert!(rig.read(1, reg::PRESENT_POSITION, 2).is_none());
        assert!(rig.read(2, reg::PRESENT_POSITION, 2).is_some());
        rig.servo(0).set_faults(Faults::NONE);
        assert!(rig.read(1, reg::PRESENT_POSITION, 2).is_some(), "recovers");
    }

    #[test]
    fn bad_checksum_fault_corrupts_every_answer() {
        let mut rig = Rig::new(&[1]);
        rig.servo(0).set_faults(Faults::BAD_CHECKSUM);
        let trace = rig.exchange(&Instruction::Ping.to_packet(1).unwrap());
        assert!(
            trace.iter().any(|b| b.from != rig.controller),
            "it does send"
        );
        assert!(rig.answers(&trace).is_empty(), "but nothing decodes");
    }

    #[test]
    fn corrupted_answers_are_counted_down_then_healthy_again() {
        let mut rig = Rig::new(&[1]);
        rig.servo(0).corrupt_next_answers(2);
        assert!(rig.read(1, reg::PRESENT_POSITION, 2).is_none());
        assert!(rig.read(1, reg::PRESENT_POSITION, 2).is_none());
        assert!(
            rig.read(1, reg::PRESENT_POSITION, 2).is_some(),
            "third is healthy"
        );
    }

    #[test]
    fn a_late_servo_answers_late_and_still_occupies_the_wire() {
        let mut rig = Rig::new(&[1]);
        let read = Instruction::Read { addr: 56, count: 2 }
            .to_packet(1)
            .unwrap();
        let on_time = rig.exchange(&read);
        let normal = rig.turnaround_ns(&on_time);
        rig.servo(0).set_faults(Faults::late_replies(500));
        let late = rig.exchange(&read);
        assert_eq!(rig.turnaround_ns(&late), normal + 500_000, "500 us later");
        assert_eq!(rig.answers(&late).len(), 1, "the whole answer still comes");
        // A late answer that meets the controller's next instruction garbles both.
        let now = rig.now_ns;
        rig.bus.take_trace();
        rig.bus
            .port(rig.controller)
            .unwrap()
            .write(&read.to_bytes());
        rig.bus.start_transmissions(now);
        rig.run_until(now + 560_000);
        let ping = Instruction::Ping.to_packet(9).unwrap();
        rig.bus
            .port(rig.controller)
            .unwrap()
            .write(&ping.to_bytes());
        rig.bus.start_transmissions(rig.now_ns);
        rig.run_for_ms(2);
        let trace = rig.bus.take_trace();
        let answer: Vec<&BusByte> = trace.iter().filter(|b| b.from != rig.controller).collect();
        assert!(!answer.is_empty(), "the late answer went on the wire");
        assert!(
            answer.iter().any(|b| b.garbled),
            "and collided with the ping: {trace:?}"
        );
    }

    #[test]
    fn dropped_answers_are_lost_evenly_or_the_next_few() {
        let mut rig = Rig::new(&[1]);
        rig.servo(0).set_faults(Faults::dropped_replies(250));
        let answered: Vec<bool> = (0..8)
            .map(|_| rig.read(1, reg::PRESENT_POSITION, 2).is_some())
            .collect();
        assert_eq!(
            answered,
            [true, true, true, false, true, true, true, false],
            "one in four"
        );
        rig.servo(0).set_faults(Faults::NONE);
        rig.servo(0).drop_next_answers(2);
        assert!(rig.read(1, reg::PRESENT_POSITION, 2).is_none());
        assert!(rig.read(1, reg::PRESENT_POSITION, 2).is_none());
        assert!(
            rig.read(1, reg::PRESENT_POSITION, 2).is_some(),
            "answers again"
        );
        assert_eq!(
            rig.servo(0).stats().replies,
            7,
            "a lost answer is not counted"
        );
    }

    #[test]
    fn lost_writes_are_missed_but_reads_still_answered() {
        let mut rig = Rig::new(&[1, 2]);
        rig.servo(0).lose_next_writes(1);
        assert!(
            rig.write(1, reg::ACCELERATION, &[7]).is_empty(),
            "missed: no answer"
        );
        assert_eq!(rig.servo(0).reg(reg::ACCELERATION), 0);
        assert!(
            rig.read(1, reg::PRESENT_POSITION, 2).is_some(),
            "reads still obeyed"
        );
        let mut sync = SyncWriteBuilder::new(reg::ACCELERATION, 1);
        sync.push(1, &[9]).unwrap();
        sync.push(2, &[9]).unwrap();
        rig.exchange(&sync.to_packet().unwrap());
        assert_eq!(
            rig.servo(0).reg(reg::ACCELERATION),
            9,
            "the next write lands"
        );
        assert_eq!(rig.servo(1).reg(reg::ACCELERATION), 9);
    }

    #[test]
    fn stalled_servo_never_arrives_and_reports_overload() {
        let mut rig = Rig::new(&[1]);
        rig.write(1, reg::TORQUE_ENABLE, &[1]);
        rig.servo(0).set_faults(Faults::STALL);
        rig.write(1, reg::MOVE_BLOCK, &move_block(0, 3000, 0));
        rig.run_for_ms(1000);
        let state = rig.read(1, reg::STATE_BLOCK, reg::STATE_BLOCK_LEN).unwrap();
        assert_eq!(state.u16_at(0), Some(2048));
        assert_eq!(state.code() & fault::OVERLOAD, fault::OVERLOAD, "ERR byte");
        assert!(
            sign_magnitude(state.u16_at(4).unwrap(), 10) > 900,
            "load near max"
        );
        assert_eq!(
            state.params()[9] & fault::OVERLOAD,
            fault::OVERLOAD,
            "status register"
        );
        assert_eq!(state.params()[10], 1, "still trying to move");
    }

    #[test]
    fn overheated_servo_reports_temperature_and_fault_bit() {
        let mut rig = Rig::new(&[1]);
        rig.servo(0).set_faults(Faults::OVERHEAT);
        let state = rig.read(1, reg::STATE_BLOCK, reg::STATE_BLOCK_LEN).unwrap();
        assert_eq!(state.code(), fault::OVERHEAT);
        assert_eq!(state.params()[7], OVERHEAT_C);
    }

    #[test]
    fn noise_before_a_packet_does_not_hide_it() {
        let mut rig = Rig::new(&[1]);
        // The start of a long packet that never finishes, then silence.
        rig.bus
            .port(rig.controller)
            .unwrap()
            .write(&[0xFF, 0xFF, 0x01, 0x40, 0x13]);
        rig.bus.start_transmissions(rig.now_ns);
        rig.run_for_ms(1);
        assert!(rig.read(1, reg::ID, 1).is_some());
        // A stray FF right before a packet is skipped too.
        let mut bytes = vec![0xFF];
        bytes.extend_from_slice(&Instruction::Ping.to_packet(1).unwrap().to_bytes());
        let trace = rig.exchange_bytes(&bytes);
        assert_eq!(rig.answers(&trace).len(), 1);
    }

    /// Present position, signed load and status register of servo 1.
    fn position_load_status(rig: &mut Rig) -> (u16, i16, u8) {
        let state = rig.read(1, reg::STATE_BLOCK, reg::STATE_BLOCK_LEN).unwrap();
        (
            state.u16_at(0).unwrap(),
            sign_magnitude(state.u16_at(4).unwrap(), 10),
            state.params()[9],
        )
    }

    #[test]
    fn an_obstacle_stops_the_shaft_and_the_load_rises_to_the_torque_limit() {
        let mut rig = Rig::new(&[1]);
        rig.write(1, reg::TORQUE_ENABLE, &[1]);
        rig.servo(0).add_obstacle(2300);
        rig.write(1, reg::MOVE_BLOCK, &move_block(0, 3000, 1000));
        rig.run_for_ms(100);
        let (position, load, _) = position_load_status(&mut rig);
        assert!(position < 2300, "still on its way: {position}");
        assert!(load < 300, "moving freely: {load}");
        rig.run_for_ms(900);
        let (position, load, status) = position_load_status(&mut rig);
        assert_eq!(position, 2300, "held at the stop");
        assert!(load >= 990, "pressing with full torque: {load}");
        assert_eq!(status & fault::OVERLOAD, 0, "not yet tripped");
        assert!(rig.servo(0).is_moving() && rig.servo(0).blocked());
    }

    #[test]
    fn pressing_on_trips_the_overload_protection_after_its_time() {
        let mut rig = Rig::new(&[1]);
        rig.write(1, reg::TORQUE_ENABLE, &[1]);
        rig.servo(0).add_obstacle(2100);
        rig.write(1, reg::MOVE_BLOCK, &move_block(0, 2600, 0));
        rig.run_for_ms(1900);
        assert_eq!(position_load_status(&mut rig).2 & fault::OVERLOAD, 0);
        rig.run_for_ms(300);
        let (position, load, status) = position_load_status(&mut rig);
        assert_eq!(
            status & fault::OVERLOAD,
            fault::OVERLOAD,
            "tripped after 2 s"
        );
        assert_eq!((position, load), (2100, 200), "protective torque only");
        // Switching torque again clears it; a goal where the shaft stands presses no more.
        rig.write(1, reg::TORQUE_ENABLE, &[0]);
        rig.write(1, reg::TORQUE_ENABLE, &[1]);
        rig.run_for_ms(10);
        let (position, load, status) = position_load_status(&mut rig);
        assert_eq!((position, status & fault::OVERLOAD), (2100, 0));
        assert!(load < 100, "holding without pressing: {load}");
    }

    #[test]
    fn setting_the_goal_back_unloads_the_shaft_and_it_moves_away_freely() {
        let mut rig = Rig::new(&[1]);
        rig.write(1, reg::TORQUE_ENABLE, &[1]);
        rig.servo(0).add_obstacle(1800);
        rig.write(1, reg::MOVE_BLOCK, &move_block(0, 1000, 0));
        rig.run_for_ms(500);
        assert_eq!(position_load_status(&mut rig).0, 1800);
        // The setpoint went on to 1000; it comes back at full acceleration (about 0.5 s).
        rig.write(1, reg::MOVE_BLOCK, &move_block(0, 1800, 0));
        rig.run_for_ms(700);
        let (_, load, _) = position_load_status(&mut rig);
        assert!(load.abs() < 100, "no more pressing: {load}");
        rig.write(1, reg::MOVE_BLOCK, &move_block(0, 2500, 0));
        rig.run_for_ms(600);
        assert_eq!(position_load_status(&mut rig).0, 2500, "away from the stop");
    }

    #[test]
    fn a_push_deflects_a_held_shaft_until_the_motor_balances_it() {
        let mut rig = Rig::new(&[1]);
        rig.write(1, reg::TORQUE_ENABLE, &[1]);
        // Factory P of servo 1 is 10: 40 thousandths of max torque per step.
        rig.servo(0).push(-400);
        rig.run_for_ms(50);
        let (position, load, _) = position_load_status(&mut rig);
        assert_eq!(position, 2038, "gives 10 steps");
        assert!((400..=450).contains(&load), "holds against it: {load}");
        // Stronger than the torque limit: the shaft is driven along.
        rig.servo(0).push(1500);
        rig.run_for_ms(100);
        let (position, load, _) = position_load_status(&mut rig);
        assert!(position > 2100, "driven: {position}");
        assert!(load <= -990, "full torque against the push: {load}");
        rig.servo(0).push(0);
        rig.run_for_ms(600);
        assert_eq!(position_load_status(&mut rig).0, 2048, "back at its goal");
    }

    #[test]
    fn speeding_up_loads_the_motor_more_than_cruising() {
        let mut rig = Rig::new(&[1]);
        rig.write(1, reg::TORQUE_ENABLE, &[1]);
        rig.write(1, reg::MOVE_BLOCK, &move_block(0, 4000, 2000));
        rig.run_for_ms(20);
        let (_, speeding_up, _) = position_load_status(&mut rig);
        rig.run_for_ms(300);
        let (_, cruising, _) = position_load_status(&mut rig);
        assert!(
            speeding_up >= 350,
            "inertia at full acceleration: {speeding_up}"
        );
        assert_eq!(cruising, 180, "friction alone at a steady speed");
    }

    #[test]
    fn a_hand_cannot_take_a_free_shaft_through_an_obstacle() {
        let mut rig = Rig::new(&[1]);
        rig.servo(0).add_obstacle(2200);
        rig.servo(0).move_by_hand(2500);
        assert_eq!(rig.servo(0).present_position(), 2200);
        rig.servo(0).clear_obstacles();
        rig.servo(0).move_by_hand(2500);
        assert_eq!(rig.servo(0).present_position(), 2500);
    }
}

//! Property: whatever arrives from the host (valid commands, out-of-range values, raw register
//! writes to any register, limit changes, garbage, truncated frames), the Atom never panics,
//! never sends a servo a goal outside the factory joint range or a gripper goal that is not an
//! encoder position, and never changes a joint's zero (its homing offset) except through a
//! calibration.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)]

mod support;

#[path = "replay_seeds/mod.rs"]
mod replay_seeds;
use replay_seeds::ReplaySeeds;

use firmware_atom::config::FACTORY_LIMITS;
use firmware_atom::{AtomConfig, JointLimit};
use proptest::prelude::*;
use protocol_core::Frame;
use protocol_core::units::Steps;
use support::rig::Rig;

/// Commands a fuzzer should hit often: motion, jog, encoders, limits, servo data, gripper,
/// frames.
const COMMANDS: &[u8] = &[
    0x05, 0x10, 0x11, 0x13, 0x16, 0x1A, 0x20, 0x21, 0x22, 0x23, 0x24, 0x25, 0x26, 0x28, 0x29, 0x2A,
    0x30, 0x31, 0x32, 0x33, 0x34, 0x3A, 0x3C, 0x3E, 0x4C, 0x4D, 0x52, 0x53, 0x54, 0x55, 0x56, 0x57,
    0x66, 0x67, 0x68, 0x81, 0x83, 0x85, 0x87, 0x89, 0x8D,
];

/// Commands that calibrate (make a servo's present position its zero).
fn calibrates(cmd: u8, data: &[u8]) -> bool {
    cmd == 0x54 || cmd == 0x68 || (cmd == 0x52 && data.get(1) == Some(&40))
}

#[derive(Clone, Debug)]
enum Input {
    /// A frame with a known command code and arbitrary data.
    Command(u8, Vec<u8>),
    /// Arbitrary bytes (noise, half frames).
    Garbage(Vec<u8>),
}

fn be(values: &[i16]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_be_bytes()).collect()
}

/// Well-formed requests whose values reach the goal path: encoders anywhere in 0..=4096,
/// angles beyond every limit, raw goal-register writes.
fn structured() -> impl Strategy<Value = Input> {
    let encoders = prop::array::uniform6(0i16..=4096);
    let angles = prop::array::uniform6(-20_000i16..20_000);
    prop_oneof![
        (encoders.clone(), prop::array::uniform6(0i16..6000)).prop_map(|(e, s)| {
            let mut d = be(&e);
            d.extend(be(&s));
            Input::Command(0x3E, d)
        }),
        (encoders, 1u8..=100).prop_map(|(e, s)| {
            let mut d = be(&e);
            d.push(s);
            Input::Command(0x3C, d)
        }),
        (angles, 1u8..=100).prop_map(|(a, s)| {
            let mut d = be(&a);
            d.push(s);
            Input::Command(0x22, d)
        }),
        (1u8..=7, register(), any::<u16>(), any::<bool>()).prop_map(|(id, addr, v, word)| {
            let mut d = vec![id, addr];
            d.extend(v.to_be_bytes());
            d.push(u8::from(word));
            Input::Command(0x52, d)
        }),
        (0x4Cu8..=0x4D, 1u8..=6, -2_000i16..2_000).prop_map(|(cmd, j, limit)| {
            let mut d = vec![j];
            d.extend(be(&[limit]));
            Input::Command(cmd, d)
        }),
        (1u8..=7, 0i16..=4096, 1u8..=100).prop_map(|(id, e, s)| {
            let mut d = vec![id];
            d.extend(be(&[e]));
            d.push(s);
            Input::Command(0x3A, d)
        }),
        (0u8..=100, 1u8..=100).prop_map(|(v, s)| Input::Command(0x67, vec![v, s])),
    ]
}

/// A register to write raw: often one that changes what a position means (limits 9..12, homing
/// offset 31..32, operating mode 33) or a neighbour, sometimes any.
fn register() -> impl Strategy<Value = u8> {
    prop_oneof![
        2 => prop::sample::select(vec![8u8, 9, 10, 11, 12, 30, 31, 32, 33, 40, 41, 42, 43, 55]),
        1 => 5u8..=70,
    ]
}

fn input() -> impl Strategy<Value = Input> {
    prop_oneof![
        3 => (prop::sample::select(COMMANDS), prop::collection::vec(any::<u8>(), 0..26))
            .prop_map(|(c, d)| Input::Command(c, d)),
        3 => structured(),
        1 => prop::collection::vec(any::<u8>(), 0..24).prop_map(Input::Garbage),
    ]
}

fn within(limit: &JointLimit, steps: i16, config: &AtomConfig, j: usize) -> bool {
    let angle = config.steps_to_angle(j, Steps(steps));
    (0..4096).contains(&steps) && limit.contains(angle)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, failure_persistence: Some(Box::new(ReplaySeeds(include_str!("safety_property.proptest-regressions")))), ..ProptestConfig::default() })]

    #[test]
    fn no_input_sends_an_out_of_limit_goal(inputs in prop::collection::vec(input(), 1..24)) {
        let config = AtomConfig { powered_at_boot: true, ..AtomConfig::default() };
        let mut rig = Rig::with(config, true);
        let zeros: Vec<u16> = (1..=7).map(|id| rig.bus.servo(id).reg_u16(31)).collect();
        let mut calibrated = false;
        for input in &inputs {
            match input {
                Input::Command(cmd, data) => {
                    calibrated |= calibrates(*cmd, data);
                    if let Some(frame) = Frame::new(*cmd, data) {
                        rig.bus.send_frame(&frame);
                    }
                }
                Input::Garbage(bytes) => {
                    rig.bus.send_raw(bytes);
                }
            }
            rig.run_ms(3);
        }
        rig.run_ms(100);
        if !calibrated {
            for id in 1..=7u8 {
                prop_assert_eq!(
                    rig.bus.servo(id).reg_u16(31),
                    zeros[usize::from(id) - 1],
                    "servo {}'s zero moved",
                    id
                );
            }
        }
        for (j, (goals, limit)) in rig.bus.goals.iter().zip(&FACTORY_LIMITS).enumerate() {
            for &g in goals {
                prop_assert!(within(limit, g, &config, j), "joint {} goal {}", j + 1, g);
            }
        }
        for &g in &rig.bus.goals[6] {
            prop_assert!((0..4096).contains(&g), "gripper goal {}", g);
        }
    }
}

/// A raw write (0x52) to any register other than torque enable, one or two bytes.
fn raw_write() -> impl Strategy<Value = (u8, u8, u16, bool)> {
    (1u8..=7, register(), any::<u16>(), any::<bool>()).prop_filter(
        "torque enable (40) is the calibration path",
        |(_, addr, _, _)| *addr != 40,
    )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, failure_persistence: Some(Box::new(ReplaySeeds(include_str!("safety_property.proptest-regressions")))), ..ProptestConfig::default() })]

    #[test]
    fn no_raw_write_moves_a_joints_zero_or_its_range(writes in prop::collection::vec(raw_write(), 1..16)) {
        let config = AtomConfig { powered_at_boot: true, ..AtomConfig::default() };
        let mut rig = Rig::with(config, true);
        rig.run_ms(20);
        let before: Vec<[u16; 3]> = (1..=7)
            .map(|id| {
                let s = rig.bus.servo(id);
                [s.reg_u16(31), s.reg_u16(9), s.reg_u16(11)]
            })
            .collect();
        for (id, addr, value, word) in writes {
            let mut d = vec![id, addr];
            d.extend(value.to_be_bytes());
            d.push(u8::from(word));
            rig.bus.send_frame(&Frame::new(0x52, &d).unwrap());
            rig.run_ms(5);
        }
        rig.run_ms(50);
        for id in 1..=7u8 {
            let s = rig.bus.servo(id);
            let after = [s.reg_u16(31), s.reg_u16(9), s.reg_u16(11)];
            prop_assert_eq!(after, before[usize::from(id) - 1], "servo {}: zero or own limits changed", id);
            prop_assert_eq!(s.reg(33), 0, "servo {} left position mode", id);
        }
    }
}

/// One sample of a host's stream: the gap before it (microseconds), its angles (centidegrees,
/// now and then past a limit) and its speed (20 % and up: the arm then crosses any distance
/// within seconds).
fn stream_sample() -> impl Strategy<Value = (u64, [i16; 6], u8)> {
    let gap = prop_oneof![
        3 => 15_000u64..25_000,
        2 => 0u64..4_000,
        1 => 0u64..200_000,
    ];
    let angle = prop_oneof![6 => -9_000i16..9_000, 1 => -20_000i16..20_000];
    (gap, prop::array::uniform6(angle), 20u8..=100)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 32, failure_persistence: None, ..ProptestConfig::default() })]

    /// Streams of any timing and any values (regular, late, in bursts, with stalls; smooth or
    /// jumping about, past the limits): whichever clock the Atom plays them on and however it
    /// bridges their gaps, no goal leaves a joint's range, and once the stream stops the arm
    /// comes to rest (within the time its slowest speed takes to cross the encoder range).
    #[test]
    fn no_stream_sends_an_out_of_limit_goal_or_runs_on(samples in prop::collection::vec(stream_sample(), 2..80)) {
        let config = AtomConfig { powered_at_boot: true, ..AtomConfig::default() };
        let mut rig = Rig::with(config, true);
        for (gap_us, angles, speed) in &samples {
            rig.run_us(*gap_us);
            let mut data = support::rig::be(angles);
            data.push(*speed);
            // As the Basic sends it: on a quiet bus, again after a collision.
            prop_assert!(rig.request(&Frame::new(0x22, &data).unwrap()).is_some(), "a sample unanswered");
        }
        // Long enough for the slowest sample's speed to cross the whole encoder range, and a
        // second for the ramps.
        let slowest = samples.iter().map(|s| s.2).min().unwrap_or(100);
        let crossing_ms = 4_096 * 1_000 / u64::from(config.joint_speed_steps(slowest));
        rig.run_ms(crossing_ms + 1_000);
        for (j, (goals, limit)) in rig.bus.goals.iter().zip(&FACTORY_LIMITS).enumerate() {
            for &g in goals {
                prop_assert!(within(limit, g, &config, j), "joint {} goal {}", j + 1, g);
            }
        }
        prop_assert_eq!(rig.ask(0x2B, &[]), vec![0u8], "still moving {} ms after the stream", crossing_ms + 1_000);
    }
}

//! The joint servos' position-loop gains (MyCobotBasic `setPid` / `getPid`, 0x2C / 0x2D).
//!
//! Six bytes on the wire: P, I and D of joints 1..3, then of joints 4..6 (the groups the seed
//! manual gives factory values for; MyCobotBasic: "p i d p i d"). Setting writes registers
//! 21..23 (P, D, I in the Feetech table) of each joint servo, with its EEPROM unlocked around
//! the writes so the gains stay after a power cycle. Getting reads them back from joint 1 and
//! joint 4 (one READ each, [`reads`]); the reply waits for both ([`crate::waiting`]), and a
//! servo that did not answer reads 255 in all three of its places (the registers hold
//! 0..=254).

use protocol_core::servo::{Packet, SyncWriteBuilder, reg};

use crate::bank::ServoBank;
use crate::config::JOINTS;
use crate::driver::Op;
use crate::error::AtomError;
use crate::settings::Settings;

/// The joint (0-based) whose gains stand for each group: joint 1 for joints 1..3, joint 4 for
/// joints 4..6.
const GROUP_JOINTS: [usize; 2] = [0, 3];

/// Joints per group.
const GROUP_SIZE: usize = 3;

/// What a gain reads as when its servo did not answer.
const NO_ANSWER: u8 = 255;

/// Servo operations a set takes: the EEPROM unlock (one SYNC WRITE), a WRITE per joint, the
/// lock.
const SET_OPS: usize = JOINTS + 2;

/// P, D, I of one group's servo, in register order.
pub type GroupGains = [u8; 3];

/// Writes `gains` (P, I, D of joints 1..3, then of joints 4..6) to the joint servos (0x2C).
pub fn set(bank: &mut ServoBank, settings: &Settings, gains: [u8; 6]) -> Result<(), AtomError> {
    if bank.op_room() < SET_OPS {
        return Err(AtomError::Busy);
    }
    let ids = &settings.config().servo_ids;
    let lock = |locked: u8| {
        let mut b = SyncWriteBuilder::new(reg::EEPROM_LOCK, 1);
        for &id in ids.iter().take(JOINTS) {
            b.push(id, &[locked])?;
        }
        b.to_packet().map(Op::Broadcast)
    };
    let (unlock, relock) = lock(0).zip(lock(1)).ok_or(AtomError::Invalid)?;
    let mut writes: heapless::Vec<Op, JOINTS> = heapless::Vec::new();
    for (j, &id) in ids.iter().take(JOINTS).enumerate() {
        let group = gains.chunks(GROUP_SIZE).nth(j / GROUP_SIZE);
        let Some(&[p, i, d]) = group else {
            return Err(AtomError::Invalid);
        };
        let write = Op::write(id, reg::P_COEFFICIENT, &[p, d, i]).ok_or(AtomError::Invalid)?;
        writes.push(write).map_err(|_| AtomError::Invalid)?;
    }
    bank.queue_op(unlock);
    for write in writes {
        bank.queue_op(write);
    }
    bank.queue_op(relock);
    Ok(())
}

/// The bus ids of the two group servos (joint 1, joint 4) a get (0x2D) reads, and their reads.
pub fn reads(settings: &Settings) -> Result<([u8; 2], [Op; 2]), AtomError> {
    let id = |j: usize| settings.config().servo_ids.get(j).copied();
    let [Some(first), Some(second)] = GROUP_JOINTS.map(id) else {
        return Err(AtomError::Invalid);
    };
    Ok(([first, second], [gain_read(first), gain_read(second)]))
}

/// One group's gains from its servo's answer ([`NO_ANSWER`] in every place without one).
pub fn group_gains(answer: Option<&Packet>) -> GroupGains {
    match answer.map(Packet::params) {
        Some(&[p, d, i]) => [p, d, i],
        _ => [NO_ANSWER; 3],
    }
}

/// The six bytes get PID answers: P, I, D of joint 1, then of joint 4.
pub fn wire_bytes([[p1, d1, i1], [p4, d4, i4]]: [GroupGains; 2]) -> [u8; 6] {
    [p1, i1, d1, p4, i4, d4]
}

/// The READ of a servo's three gain registers (21..23).
fn gain_read(id: u8) -> Op {
    Op::Read {
        id,
        addr: reg::P_COEFFICIENT,
        count: 3,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bank::test_support::{at_rest, powered, queued};

    #[test]
    fn set_writes_p_d_i_of_each_group_between_an_eeprom_unlock_and_lock() {
        let (settings, mut bank) = at_rest();
        assert_eq!(set(&mut bank, &settings, [1, 2, 3, 4, 5, 6]), Ok(()));
        let ops = queued(&mut bank, &settings);
        assert_eq!(ops.len(), SET_OPS);
        assert!(matches!(ops[0], Op::Broadcast(_)), "unlock");
        assert!(matches!(ops[SET_OPS - 1], Op::Broadcast(_)), "lock");
        for (j, op) in ops[1..=JOINTS].iter().enumerate() {
            let pdi: &[u8] = if j < GROUP_SIZE {
                &[1, 3, 2]
            } else {
                &[4, 6, 5]
            };
            let id = u8::try_from(j + 1).unwrap();
            assert_eq!(*op, Op::write(id, reg::P_COEFFICIENT, pdi).unwrap());
        }
    }

    #[test]
    fn get_answers_p_i_d_of_joints_1_and_4_and_255_for_a_silent_servo() {
        let settings = powered();
        let (ids, ops) = reads(&settings).unwrap();
        assert_eq!(ids, [1, 4]);
        assert_eq!(ops[1], gain_read(4));
        let answer = Packet::new(1, 0, &[10, 30, 20]).unwrap();
        let got = [group_gains(Some(&answer)), group_gains(None)];
        assert_eq!(wire_bytes(got), [10, 20, 30, 255, 255, 255]);
    }
}

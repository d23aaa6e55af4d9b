//! The joint servos' position-loop gains (MyCobotBasic `setPid` / `getPid`, 0x2C / 0x2D).
//!
//! Six bytes on the wire: P, I and D of joints 1..3, then of joints 4..6 (the groups the seed
//! manual gives factory values for; MyCobotBasic: "p i d p i d"). Setting writes registers
//! 21..23 (P, D, I in the Feetech table) of each joint servo, with its EEPROM unlocked around
//! the writes so the gains stay after a power cycle. Getting reads them back from joint 1 and
//! joint 4 (one READ each) and answers when both reads have finished; a servo that did not
//! answer reads 255 in all three of its places (the registers hold 0..=254).

use protocol_core::Frame;
use protocol_core::command::{Reply, cmd};
use protocol_core::servo::{SyncWriteBuilder, reg};

use crate::bank::{ServoBank, Then};
use crate::config::JOINTS;
use crate::driver::{Op, Outcome};
use crate::error::AtomError;
use crate::link::Link;
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

/// A get (0x2D) waiting for its two reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Reading {
    link: Link,
    /// Bus id of each group's servo.
    ids: [u8; 2],
    /// P, D, I (register order) of each group, once read.
    got: [Option<[u8; 3]>; 2],
}

/// The gains part. See the [module doc](self).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Gains {
    reading: Option<Reading>,
}

impl Gains {
    /// Writes `gains` (P, I, D of joints 1..3, then of joints 4..6) to the joint servos (0x2C).
    pub fn set(
        &self,
        bank: &mut ServoBank,
        settings: &Settings,
        gains: [u8; 6],
    ) -> Result<(), AtomError> {
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
        bank.queue_op(unlock, Then::Nothing);
        for write in writes {
            bank.queue_op(write, Then::Nothing);
        }
        bank.queue_op(relock, Then::Nothing);
        Ok(())
    }

    /// Starts reading the gains back (0x2D); the reply goes to `link` from [`Gains::finished`].
    pub fn read(
        &mut self,
        bank: &mut ServoBank,
        settings: &Settings,
        link: Link,
    ) -> Result<(), AtomError> {
        if self.reading.is_some() || bank.op_room() < GROUP_JOINTS.len() {
            return Err(AtomError::Busy);
        }
        let id = |j: usize| settings.config().servo_ids.get(j).copied();
        let ids = GROUP_JOINTS.map(id);
        let [Some(first), Some(second)] = ids else {
            return Err(AtomError::Invalid);
        };
        let ids = [first, second];
        for id in ids {
            bank.queue_op(gain_read(id), Then::Nothing);
        }
        self.reading = Some(Reading {
            link,
            ids,
            got: [None; 2],
        });
        Ok(())
    }

    /// Takes note of a finished servo operation; the reply of a get once both of its reads are
    /// done. `retrying` says the bank will try `op` again (it timed out with tries left).
    pub fn finished(
        &mut self,
        op: &Op,
        outcome: &Outcome,
        retrying: bool,
    ) -> Option<(Link, Frame)> {
        let reading = self.reading.as_mut()?;
        let group = reading.ids.iter().position(|&id| *op == gain_read(id))?;
        let values = match outcome {
            Outcome::Answered(p) => match p.params() {
                &[p, d, i] => [p, d, i],
                _ => [NO_ANSWER; 3],
            },
            _ if retrying => return None,
            _ => [NO_ANSWER; 3],
        };
        if let Some(slot) = reading.got.get_mut(group) {
            *slot = Some(values);
        }
        let [Some([p1, d1, i1]), Some([p4, d4, i4])] = reading.got else {
            return None;
        };
        let link = reading.link;
        self.reading = None;
        let reply: Frame = Reply::Bytes6([p1, i1, d1, p4, i4, d4]).to_frame(cmd::GET_PID);
        Some((link, reply))
    }
}

/// The READ of a servo's three gain registers (21..23).
fn gain_read(id: u8) -> Op {
    Op::Read {
        id,
        addr: reg::P_COEFFICIENT,
        count: 3,
    }
}

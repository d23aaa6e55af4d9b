//! Backup and restore of each servo's parameters (0xEA / 0xEB) in the Atom's flash.
//!
//! A backup reads the servo's EEPROM block, registers [`BLOCK_ADDR`] ..
//! `BLOCK_ADDR + BLOCK_LEN` (9..=39: angle limits, temperature, voltage and torque limits,
//! PID, start-up force, dead zones, protection settings, homing offset, operating mode, speed
//! loop gains: what a replaced or corrupted servo needs), and stores it under the servo's id in
//! the Atom's flash ([`ParamStore`], `flash_store` on the board and in the virtual robot),
//! through [`crate::flash_writes`]: in force at once, written once the arm is quiet, and then
//! it survives a power cycle. The reply waits for every block to be read
//! ([`crate::waiting`]): `01`, or `00` if a servo did not answer.
//!
//! A restore writes a stored block back (EEPROM unlocked and locked around it), after the same
//! checks as any raw write: never the id, baud rate, return delay or status return level (they
//! are not in the block), only a block in position mode (operating mode 0), never without a
//! backup (`00`). The homing offset is part of the block; if restoring it moves the joint's
//! zero, the servo is released first (holding its old goal in the new frame would make it jump)
//! and stays released until powered on or focused again, which holds it where it is. The
//! joint limits still apply to every goal afterwards.

use flash_store::StoreError;
use protocol_core::command::ServoSelect;
use protocol_core::servo::{Packet, reg};

use crate::config::JOINTS;
use crate::context::Context;
use crate::driver::Op;
use crate::error::AtomError;
use crate::motion::MotionController;
use crate::store::ParamStore;

/// First register of the parameter block.
pub const BLOCK_ADDR: u8 = reg::MIN_POSITION;
/// Length of the parameter block: registers 9..=39.
pub const BLOCK_LEN: usize = 31;

/// One servo's parameter block.
pub type Block = [u8; BLOCK_LEN];

/// Offset of the homing offset (registers 31..=32) in a block.
const HOMING_OFFSET_AT: usize = (reg::HOMING_OFFSET - BLOCK_ADDR) as usize;
/// Offset of the operating mode (register 33) in a block.
const MODE_AT: usize = (reg::OPERATING_MODE - BLOCK_ADDR) as usize;

/// The block stored for servo `id` in `store`, if any (a record of another length is
/// corrupt).
fn load(store: &mut dyn ParamStore, id: u8) -> Result<Option<Block>, StoreError> {
    let mut block = [0u8; BLOCK_LEN];
    match store.fetch(id, &mut block)? {
        Some(BLOCK_LEN) => Ok(Some(block)),
        Some(_) => Err(StoreError::Corrupted),
        None => Ok(None),
    }
}

/// The reads of a backup (0xEA) or restore (0xEB) of `servos`: each servo's present block,
/// and the servos read (a bit per index). Refused with no store (`has_store`), or without room
/// in the bank's queue for a restore's writes afterwards (three operations per servo).
pub fn reads(
    cx: &Context<'_>,
    servos: ServoSelect,
    has_store: bool,
) -> Result<(heapless::Vec<Op, JOINTS>, u8), AtomError> {
    if !has_store {
        return Err(AtomError::Invalid);
    }
    let indices = match servos {
        ServoSelect::All => 0..JOINTS,
        ServoSelect::One(s) => {
            let i = s.index();
            i..i + 1
        }
    };
    if cx.bank.op_room() < indices.len() * 4 {
        return Err(AtomError::Busy);
    }
    let mut ops = heapless::Vec::new();
    let mut servos = 0u8;
    for i in indices {
        let id = *cx
            .settings
            .config()
            .servo_ids
            .get(i)
            .ok_or(AtomError::Invalid)?;
        let read = Op::Read {
            id,
            addr: BLOCK_ADDR,
            count: BLOCK_LEN as u8,
        };
        ops.push(read).map_err(|_| AtomError::Busy)?;
        servos |= 1 << i;
    }
    Ok((ops, servos))
}

/// Servo `index`'s parameter block from its answer to the read of [`reads`]; `None` if it did
/// not answer.
pub fn block(answer: Option<&Packet>) -> Option<Block> {
    answer.and_then(|p| p.params().try_into().ok())
}

/// Takes servo `index`'s present block (`None`: it did not answer): a backup stores it, a
/// restore writes the stored one back. True if that worked.
pub fn take_block(
    cx: &mut Context<'_>,
    motion: &mut MotionController,
    store: Option<&mut dyn ParamStore>,
    restoring: bool,
    index: usize,
    present: Option<Block>,
) -> bool {
    let id = cx.settings.config().servo_ids.get(index).copied();
    match (present, store, id) {
        (Some(block), Some(store), Some(id)) if !restoring => store.store(id, &block).is_ok(),
        (Some(block), Some(store), Some(id)) => match load(store, id) {
            Ok(Some(saved)) => restore(cx, motion, index, id, &block, &saved),
            _ => false,
        },
        _ => false,
    }
}

/// Writes `saved` back to servo `index` (bus id `id`) whose block is `present` now. See the
/// [module doc](self).
fn restore(
    cx: &mut Context<'_>,
    motion: &mut MotionController,
    index: usize,
    id: u8,
    present: &Block,
    saved: &Block,
) -> bool {
    if saved.get(MODE_AT) != Some(&0) {
        return false;
    }
    let offset = HOMING_OFFSET_AT..HOMING_OFFSET_AT + 2;
    if present.get(offset.clone()) != saved.get(offset) {
        // The zero moves: the servo would jump to its old goal in the new frame.
        if index < JOINTS {
            motion.halt(cx);
        }
        if !cx.bank.set_torque(cx.settings, index, false) {
            return false;
        }
    }
    let ops = [
        Op::write(id, reg::EEPROM_LOCK, &[0]),
        Op::write(id, BLOCK_ADDR, saved),
        Op::write(id, reg::EEPROM_LOCK, &[1]),
    ];
    if cx.bank.op_room() < ops.len() {
        return false;
    }
    ops.into_iter()
        .all(|op| op.is_some_and(|op| cx.bank.queue_op(op)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bank::test_support::{at_rest, queued};

    use crate::store::test_support::Memory;

    /// A block in position mode, every other byte `fill`, the homing offset `homing_offset`.
    fn block(fill: u8, homing_offset: u8) -> Block {
        let mut b = [fill; BLOCK_LEN];
        b[MODE_AT] = 0;
        b[HOMING_OFFSET_AT] = homing_offset;
        b[HOMING_OFFSET_AT + 1] = 0;
        b
    }

    /// Takes `present` as joint 2's block (bus id 2) for a backup or a restore, with `saved`
    /// in the store: whether that worked, what it queued, whether the joint still holds torque,
    /// and the store.
    fn take_joint_2(
        restoring: bool,
        saved: Option<Block>,
        present: Option<Block>,
    ) -> (bool, std::vec::Vec<Op>, bool, Memory) {
        let (settings, mut bank) = at_rest();
        let mut store = Memory::default();
        if let Some(saved) = saved {
            store.store(2, &saved).unwrap();
        }
        let cx = &mut Context::new(0, &mut bank, &settings);
        let mut motion = MotionController::new();
        let ok = take_block(cx, &mut motion, Some(&mut store), restoring, 1, present);
        let ops = queued(&mut bank, &settings);
        (ok, ops, bank.enabled(1), store)
    }

    #[test]
    fn a_backup_stores_the_block_under_the_servo_id() {
        let (ok, ops, _, mut store) = take_joint_2(false, None, Some(block(7, 0)));
        assert!(ok && ops.is_empty());
        assert_eq!(load(&mut store, 2), Ok(Some(block(7, 0))));
        assert!(!take_joint_2(false, None, None).0, "no answer");
    }

    #[test]
    fn a_restore_writes_the_saved_block_back_with_the_eeprom_open() {
        let (ok, ops, holds, _) = take_joint_2(true, Some(block(9, 0)), Some(block(4, 0)));
        assert!(ok);
        assert_eq!(
            ops,
            [
                Op::write(2, reg::EEPROM_LOCK, &[0]).unwrap(),
                Op::write(2, BLOCK_ADDR, &block(9, 0)).unwrap(),
                Op::write(2, reg::EEPROM_LOCK, &[1]).unwrap(),
            ]
        );
        assert!(holds, "the zero stayed: the servo holds on");
    }

    #[test]
    fn a_restore_that_moves_the_zero_releases_the_servo_first() {
        let (ok, ops, holds, _) = take_joint_2(true, Some(block(9, 30)), Some(block(9, 0)));
        assert!(ok);
        assert_eq!(ops[0], Op::write(2, reg::TORQUE_ENABLE, &[0]).unwrap());
        assert_eq!(ops.len(), 4);
        assert!(!holds);
    }

    #[test]
    fn a_restore_needs_a_backup_in_position_mode() {
        let (ok, ops, _, _) = take_joint_2(true, None, Some(block(9, 0)));
        assert!(!ok && ops.is_empty(), "no backup");
        let mut wheel = block(9, 0);
        wheel[MODE_AT] = 1;
        let (ok, ops, _, _) = take_joint_2(true, Some(wheel), Some(block(9, 0)));
        assert!(!ok && ops.is_empty(), "not in position mode");
    }

    #[test]
    fn the_reads_cover_the_servos_asked_for_with_room_for_the_writes() {
        let (settings, mut bank) = at_rest();
        let cx = Context::new(0, &mut bank, &settings);
        let (ops, servos) = reads(&cx, ServoSelect::All, true).unwrap();
        assert_eq!((ops.len(), servos), (JOINTS, 0b11_1111));
        assert_eq!(reads(&cx, ServoSelect::All, false), Err(AtomError::Invalid));
    }
}

//! Replies that wait on servo reads: the one completion path.
//!
//! Most requests are answered at once from cached state. A read-and-reply command (get servo
//! data 0x53, get PID 0x2D, backup / restore 0xEA / 0xEB) instead queues its servo reads in
//! the bank with a [`Ticket`] and waits here as one [`WaitingRead`]; the bank hands every read
//! back with its ticket once it is done (answered, or out of retries), and [`WaitingReads::complete`]
//! turns it into the reply when the request has all it waited for. A new read-and-reply
//! command is one new variant of [`WaitingRead`] and its arm in `complete`.

use protocol_core::Frame;
use protocol_core::command::{Reply, cmd};

use crate::backup;
use crate::bank::{Finished, OP_QUEUE, ServoBank, Ticket};
use crate::config::SERVOS;
use crate::context::Context;
use crate::driver::Op;
use crate::error::AtomError;
use crate::gains::{self, GroupGains};
use crate::link::Link;
use crate::motion::MotionController;
use crate::store::ParamStore;

/// Requests that can wait at once: as many as the bank has servo operations.
pub const WAITING: usize = OP_QUEUE;

/// What a request waiting for servo reads does with them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WaitingRead {
    /// Get servo data (0x53): one read of one or two bytes, answered with the value (-1, or
    /// 0xFF for one byte, if the servo did not answer).
    ServoData {
        /// True for the 2-byte form.
        two_bytes: bool,
    },
    /// Get PID (0x2D): the gains of the servos of joints 1 and 4, answered once both are in.
    Pid {
        /// Bus id of each group's servo.
        ids: [u8; 2],
        /// Each group's gains, once read.
        got: [Option<GroupGains>; 2],
    },
    /// Backup (0xEA) or restore (0xEB): every selected servo's parameter block, answered `01`
    /// once all are stored or written back, `00` if one failed.
    Params {
        /// True for a restore.
        restore: bool,
        /// Servos (a bit per index) still to be read.
        waiting: u8,
        /// True while every servo so far worked.
        ok: bool,
    },
}

impl WaitingRead {
    /// True for a kind of request that runs one at a time (get PID, backup / restore).
    fn exclusive_with(&self, other: &Self) -> bool {
        matches!(
            (self, other),
            (Self::Pid { .. }, Self::Pid { .. }) | (Self::Params { .. }, Self::Params { .. })
        )
    }
}

/// A request waiting for its reads, and where its reply goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Waiter {
    link: Link,
    read: WaitingRead,
}

/// The requests waiting for servo reads. See the [module doc](self).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct WaitingReads {
    waiters: [Option<Waiter>; WAITING],
}

impl WaitingReads {
    /// True if no request waits for its reads.
    pub fn is_empty(&self) -> bool {
        self.waiters.iter().all(Option::is_none)
    }

    /// Queues `ops` in `bank` for a request from `link` that waits as `read`. Refused
    /// ([`AtomError::Busy`]) while one of its kind runs that must run alone, or without room.
    pub fn start(
        &mut self,
        bank: &mut ServoBank,
        link: Link,
        read: WaitingRead,
        ops: &[Op],
    ) -> Result<(), AtomError> {
        let running = self.waiters.iter().flatten();
        if running.map(|w| &w.read).any(|r| r.exclusive_with(&read)) || bank.op_room() < ops.len() {
            return Err(AtomError::Busy);
        }
        let (slot, free) = self
            .waiters
            .iter_mut()
            .enumerate()
            .find(|(_, w)| w.is_none())
            .ok_or(AtomError::Busy)?;
        let ticket = Ticket(u8::try_from(slot).map_err(|_| AtomError::Busy)?);
        for op in ops {
            if !bank.queue_read(op.clone(), ticket) {
                return Err(AtomError::Busy);
            }
        }
        *free = Some(Waiter { link, read });
        Ok(())
    }

    /// The one completion path: takes a read the bank is done with and returns the reply of
    /// its request once that has everything it waited for, and the link it goes to. A restore
    /// acts on the servos (`cx`, `motion`) and the flash (`store`) on the way.
    pub fn complete(
        &mut self,
        cx: &mut Context<'_>,
        motion: &mut MotionController,
        store: Option<&mut dyn ParamStore>,
        done: Finished,
    ) -> Option<(Link, Frame)> {
        let slot = self.waiters.get_mut(usize::from(done.ticket.0))?;
        let waiter = slot.as_mut()?;
        let answer = done.answer.as_ref();
        let reply = match &mut waiter.read {
            WaitingRead::ServoData { two_bytes: true } => {
                let value = answer.and_then(|p| p.u16_at(0)).map_or(-1, |v| v as i16);
                Some(Reply::Int16(value).to_frame(cmd::GET_SERVO_DATA))
            }
            WaitingRead::ServoData { two_bytes: false } => {
                // A servo that does not answer reads FF, as 0xE4 reports one.
                let value = answer.and_then(|p| p.params().first()).map_or(0xFF, |&v| v);
                Some(Reply::Byte(value).to_frame(cmd::GET_SERVO_DATA))
            }
            WaitingRead::Pid { ids, got } => {
                let group = ids.iter().position(|&id| id == done.id)?;
                if let Some(slot) = got.get_mut(group) {
                    *slot = Some(gains::group_gains(answer));
                }
                let [Some(first), Some(second)] = *got else {
                    return None;
                };
                let bytes = gains::wire_bytes([first, second]);
                Some(Reply::Bytes6(bytes).to_frame(cmd::GET_PID))
            }
            WaitingRead::Params {
                restore,
                waiting,
                ok,
            } => {
                let servo_ids = &cx.settings.config().servo_ids;
                let index = servo_ids.iter().position(|&id| id == done.id)?;
                if index >= SERVOS || *waiting & (1 << index) == 0 {
                    return None;
                }
                *waiting &= !(1 << index);
                let block = backup::block(answer);
                *ok &= backup::take_block(cx, motion, store, *restore, index, block);
                if *waiting != 0 {
                    return None;
                }
                let code = if *restore {
                    cmd::RESTORE_SERVO_PARAMS
                } else {
                    cmd::BACKUP_SERVO_PARAMS
                };
                Some(Reply::Byte(u8::from(*ok)).to_frame(code))
            }
        };
        let link = waiter.link;
        *slot = None;
        Some((link, reply?))
    }
}

#[cfg(test)]
mod tests {
    use protocol_core::servo::Packet;

    use super::*;
    use crate::bank::test_support::at_rest;
    use crate::driver::Outcome;

    fn read(id: u8, addr: u8, count: u8) -> Op {
        Op::Read { id, addr, count }
    }

    #[test]
    fn each_read_and_reply_command_is_answered_through_complete() {
        let (settings, mut bank) = at_rest();
        let mut motion = MotionController::new();
        let mut waiting = WaitingReads::default();
        let word = WaitingRead::ServoData { two_bytes: true };
        assert_eq!(
            waiting.start(&mut bank, Link::Usb, word, &[read(2, 56, 2)]),
            Ok(())
        );
        let pid = WaitingRead::Pid {
            ids: [1, 4],
            got: [None; 2],
        };
        let pid_reads = [read(1, 21, 3), read(4, 21, 3)];
        assert_eq!(waiting.start(&mut bank, Link::Bus, pid, &pid_reads), Ok(()));
        assert_eq!(
            waiting.start(&mut bank, Link::Bus, pid, &pid_reads),
            Err(AtomError::Busy),
            "one get PID at a time"
        );
        let answers = [
            Packet::new(2, 0, &[0x34, 0x12]),
            Packet::new(1, 0, &[10, 30, 20]),
            None,
        ];
        let mut replies = std::vec::Vec::new();
        for answer in answers {
            let op = bank.due_job().unwrap();
            let outcome = answer.map_or(Outcome::TimedOut, Outcome::Answered);
            for _ in 0..=settings.config().timing.retries {
                if let Some(done) = bank.finish(0, &settings, op.clone(), outcome.clone(), false) {
                    let cx = &mut Context::new(0, &mut bank, &settings);
                    replies.push(waiting.complete(cx, &mut motion, None, done));
                    break;
                }
            }
        }
        let servo_data = Frame::new(cmd::GET_SERVO_DATA, &[0x12, 0x34]).unwrap();
        let gains = Reply::Bytes6([10, 20, 30, 255, 255, 255]).to_frame(cmd::GET_PID);
        assert_eq!(
            replies,
            [
                Some((Link::Usb, servo_data)),
                None,
                Some((Link::Bus, gains))
            ],
            "get PID answers once both reads are done, a silent servo as 255"
        );
        assert_eq!(waiting, WaitingReads::default(), "nobody waits any more");
    }

    #[test]
    fn a_backup_answers_once_every_servo_is_in() {
        let (settings, mut bank) = at_rest();
        let mut motion = MotionController::new();
        let mut waiting = WaitingReads::default();
        let params = WaitingRead::Params {
            restore: false,
            waiting: 0b11,
            ok: true,
        };
        let reads = [read(1, 9, 31), read(2, 9, 31)];
        assert_eq!(waiting.start(&mut bank, Link::Bus, params, &reads), Ok(()));
        let mut replies = std::vec::Vec::new();
        for _ in 0..2 {
            let op = bank.due_job().unwrap();
            let block = Packet::new(op.id(), 0, &[0; 31]);
            let done = bank.finish(0, &settings, op, Outcome::Answered(block.unwrap()), false);
            let cx = &mut Context::new(0, &mut bank, &settings);
            replies.push(waiting.complete(cx, &mut motion, None, done.unwrap()));
        }
        let failed = Frame::new(cmd::BACKUP_SERVO_PARAMS, &[0]).unwrap();
        assert_eq!(replies, [None, Some((Link::Bus, failed))], "no store: 00");
    }
}

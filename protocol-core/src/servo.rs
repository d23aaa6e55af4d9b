//! Feetech STS servo packets (`docs/servo-bus.md`).
//!
//! ```text
//! instruction:  FF FF ID LEN INSTR P1..Pn CHK      LEN = n + 2
//! status:       FF FF ID LEN ERR   D1..Dn CHK      LEN = n + 2
//! CHK = ~(ID + LEN + INSTR/ERR + sum(P)) & 0xFF
//! ```
//!
//! Both directions share one layout, so one [`Packet`] type and one streaming
//! [`PacketDecoder`] serve the servo driver (reading status packets) and the simulated servos
//! (reading instructions). [`Instruction`] is the typed meaning of an instruction packet.
//! Register values are little-endian and sign-magnitude ([`sign_magnitude`]); the host protocol
//! is big-endian two's complement, and these helpers are the only place that knows it.

use heapless::Vec;

use crate::scanner::{Format, Scan, Scanner};

/// First two bytes of every servo packet.
pub const HEADER: u8 = 0xFF;
/// The broadcast id: every servo obeys, none replies.
pub const BROADCAST_ID: u8 = 0xFE;
/// Highest id a servo can have.
pub const MAX_ID: u8 = 0xFC;
/// Most parameter bytes a packet may carry. The largest packet we send is a SYNC WRITE of the
/// 7-byte move block to 7 servos: 2 + 7 * (1 + 7) = 58 parameters.
pub const MAX_PARAMS: usize = 96;
/// Most bytes of one encoded packet: `FF FF ID LEN CODE` + params + CHK.
pub const MAX_PACKET_BYTES: usize = MAX_PARAMS + 6;

/// Instruction codes.
pub mod instruction {
    /// Answer with an empty status packet.
    pub const PING: u8 = 0x01;
    /// Read `count` bytes from `addr`.
    pub const READ: u8 = 0x02;
    /// Write bytes from `addr`.
    pub const WRITE: u8 = 0x03;
    /// Write held until ACTION.
    pub const REG_WRITE: u8 = 0x04;
    /// Apply held REG WRITEs.
    pub const ACTION: u8 = 0x05;
    /// Factory reset.
    pub const RESET: u8 = 0x0A;
    /// Read the same registers of several servos; each answers in turn.
    pub const SYNC_READ: u8 = 0x82;
    /// Write the same registers of several servos; nobody answers.
    pub const SYNC_WRITE: u8 = 0x83;
}

/// Fault bits of a status packet's ERR byte (and of register 65).
pub mod fault {
    /// Input voltage out of range.
    pub const VOLTAGE: u8 = 1;
    /// Magnetic angle sensor fault.
    pub const ANGLE_SENSOR: u8 = 2;
    /// Over temperature.
    pub const OVERHEAT: u8 = 4;
    /// Over current.
    pub const OVERCURRENT: u8 = 8;
    /// Overload (stall).
    pub const OVERLOAD: u8 = 32;
}

/// Control-table addresses of the STS/SMS series (`docs/servo-bus.md`).
pub mod reg {
    /// Firmware major version (ro).
    pub const FIRMWARE_MAJOR: u8 = 0;
    /// Firmware minor version (ro).
    pub const FIRMWARE_MINOR: u8 = 1;
    /// Model number, 2 bytes (ro).
    pub const MODEL: u8 = 3;
    /// Servo id.
    pub const ID: u8 = 5;
    /// Baud rate (0 = 1 Mbaud).
    pub const BAUD_RATE: u8 = 6;
    /// Return delay in 2 us units.
    pub const RETURN_DELAY: u8 = 7;
    /// Status return level: 0 only PING/READ reply, 1 every instruction replies.
    pub const STATUS_RETURN_LEVEL: u8 = 8;
    /// Minimum position limit, 2 bytes.
    pub const MIN_POSITION: u8 = 9;
    /// Maximum position limit, 2 bytes.
    pub const MAX_POSITION: u8 = 11;
    /// Maximum temperature, deg C.
    pub const MAX_TEMPERATURE: u8 = 13;
    /// Maximum voltage, 0.1 V.
    pub const MAX_VOLTAGE: u8 = 14;
    /// Minimum voltage, 0.1 V.
    pub const MIN_VOLTAGE: u8 = 15;
    /// Maximum torque, 2 bytes.
    pub const MAX_TORQUE: u8 = 16;
    /// Unloading condition.
    pub const UNLOADING_CONDITION: u8 = 19;
    /// LED alarm condition.
    pub const LED_ALARM: u8 = 20;
    /// Position loop P coefficient.
    pub const P_COEFFICIENT: u8 = 21;
    /// Position loop D coefficient.
    pub const D_COEFFICIENT: u8 = 22;
    /// Position loop I coefficient.
    pub const I_COEFFICIENT: u8 = 23;
    /// Minimum startup force, 2 bytes.
    pub const MIN_STARTUP_FORCE: u8 = 24;
    /// Clockwise dead zone.
    pub const CW_DEAD_ZONE: u8 = 26;
    /// Counter-clockwise dead zone.
    pub const CCW_DEAD_ZONE: u8 = 27;
    /// Homing offset, 2 bytes, sign bit 11.
    pub const HOMING_OFFSET: u8 = 31;
    /// Operating mode (0 position).
    pub const OPERATING_MODE: u8 = 33;
    /// Overload torque.
    pub const OVERLOAD_TORQUE: u8 = 36;
    /// Torque enable: 0 off, 1 on, 128 current position becomes 2048.
    pub const TORQUE_ENABLE: u8 = 40;
    /// Acceleration (100 steps/s^2 units).
    pub const ACCELERATION: u8 = 41;
    /// Goal position, 2 bytes, sign bit 15.
    pub const GOAL_POSITION: u8 = 42;
    /// Goal time, 2 bytes.
    pub const GOAL_TIME: u8 = 44;
    /// Goal speed, 2 bytes (steps/s).
    pub const GOAL_SPEED: u8 = 46;
    /// Torque limit, 2 bytes.
    pub const TORQUE_LIMIT: u8 = 48;
    /// EEPROM lock: 0 unlocked, 1 locked.
    pub const EEPROM_LOCK: u8 = 55;
    /// Present position, 2 bytes, sign bit 15.
    pub const PRESENT_POSITION: u8 = 56;
    /// Present speed, 2 bytes, sign bit 15.
    pub const PRESENT_SPEED: u8 = 58;
    /// Present load, 2 bytes, sign bit 10.
    pub const PRESENT_LOAD: u8 = 60;
    /// Present voltage, 0.1 V.
    pub const PRESENT_VOLTAGE: u8 = 62;
    /// Present temperature, deg C.
    pub const PRESENT_TEMPERATURE: u8 = 63;
    /// Status (fault bits).
    pub const STATUS: u8 = 65;
    /// Moving flag.
    pub const MOVING: u8 = 66;
    /// Present current, 2 bytes, sign bit 15.
    pub const PRESENT_CURRENT: u8 = 69;
    /// Size of the control table the simulated servo models (addresses 0..=70).
    pub const TABLE_SIZE: usize = 71;
    /// First byte of a move block (acceleration, goal position, goal time, goal speed).
    pub const MOVE_BLOCK: u8 = ACCELERATION;
    /// Length of a move block.
    pub const MOVE_BLOCK_LEN: u8 = 7;
    /// First byte of the present-state block (position .. moving).
    pub const STATE_BLOCK: u8 = PRESENT_POSITION;
    /// Length of the present-state block: addresses 56..=70.
    pub const STATE_BLOCK_LEN: u8 = 15;
}

/// The checksum of a packet: `~(id + len + code + sum(params)) & 0xFF`.
pub fn checksum(id: u8, len: u8, code: u8, params: &[u8]) -> u8 {
    let sum = params
        .iter()
        .fold(id.wrapping_add(len).wrapping_add(code), |acc, &b| {
            acc.wrapping_add(b)
        });
    !sum
}

/// Decodes a sign-magnitude register value whose sign is bit `sign_bit` (15 for position,
/// speed and current, 10 for load, 11 for the homing offset).
pub fn sign_magnitude(raw: u16, sign_bit: u8) -> i16 {
    let sign_bit = sign_bit.min(15);
    let magnitude = (raw & ((1u16 << sign_bit) - 1)) as i16;
    if raw & (1 << sign_bit) != 0 {
        -magnitude
    } else {
        magnitude
    }
}

/// Encodes `value` as sign-magnitude with the sign in bit `sign_bit`; the magnitude is
/// saturated to the bits below the sign.
pub fn to_sign_magnitude(value: i16, sign_bit: u8) -> u16 {
    let sign_bit = sign_bit.min(15);
    let max = (1u16 << sign_bit) - 1;
    let magnitude = value.unsigned_abs().min(max);
    if value < 0 {
        magnitude | (1 << sign_bit)
    } else {
        magnitude
    }
}

/// One servo packet, instruction or status: the id, the code (INSTR or ERR) and the parameters.
#[derive(Clone, PartialEq, Eq, Hash, Default)]
pub struct Packet {
    id: u8,
    code: u8,
    params: Vec<u8, MAX_PARAMS>,
}

impl Packet {
    /// A packet; `None` if `params` is longer than [`MAX_PARAMS`].
    pub fn new(id: u8, code: u8, params: &[u8]) -> Option<Self> {
        Some(Self {
            id,
            code,
            params: Vec::from_slice(params).ok()?,
        })
    }

    /// The servo id (or [`BROADCAST_ID`]).
    pub fn id(&self) -> u8 {
        self.id
    }

    /// The instruction code (host to servo) or the fault bits (servo to host).
    pub fn code(&self) -> u8 {
        self.code
    }

    /// The parameter (or data) bytes.
    pub fn params(&self) -> &[u8] {
        &self.params
    }

    /// The LEN byte: number of parameters + 2.
    pub fn len_byte(&self) -> u8 {
        // params.len() <= MAX_PARAMS = 96.
        self.params.len() as u8 + 2
    }

    /// Number of bytes [`Packet::encode`] writes.
    pub fn encoded_len(&self) -> usize {
        self.params.len() + 6
    }

    /// Writes the packet's wire bytes into `out`; returns how many, or `None` if `out` is short.
    pub fn encode(&self, out: &mut [u8]) -> Option<usize> {
        let n = self.encoded_len();
        let out = out.get_mut(..n)?;
        let (head, rest) = out.split_at_mut(5);
        head.copy_from_slice(&[HEADER, HEADER, self.id, self.len_byte(), self.code]);
        let (params, chk) = rest.split_at_mut(self.params.len());
        params.copy_from_slice(&self.params);
        chk.copy_from_slice(&[checksum(self.id, self.len_byte(), self.code, &self.params)]);
        Some(n)
    }

    /// The packet's wire bytes.
    pub fn to_bytes(&self) -> Vec<u8, MAX_PACKET_BYTES> {
        let mut buf = [0u8; MAX_PACKET_BYTES];
        let n = self.encode(&mut buf).unwrap_or(0);
        Vec::from_slice(buf.get(..n).unwrap_or(&[])).unwrap_or_default()
    }

    /// The little-endian u16 at parameter offset `i`, if present.
    pub fn u16_at(&self, i: usize) -> Option<u16> {
        let lo = *self.params.get(i)?;
        let hi = *self.params.get(i + 1)?;
        Some(u16::from_le_bytes([lo, hi]))
    }
}

impl core::fmt::Debug for Packet {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "Packet {{ id: {}, code: {:#04x}, params: {:02x?} }}",
            self.id,
            self.code,
            self.params.as_slice()
        )
    }
}

/// Why an instruction packet has no meaning.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InstructionError {
    /// The code is not an STS instruction.
    UnknownInstruction(u8),
    /// The parameters do not fit the instruction's layout.
    BadParameters,
}

/// The typed meaning of an instruction packet. Borrows the packet's parameters.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Instruction<'a> {
    /// Answer with an empty status packet.
    Ping,
    /// Read `count` bytes from `addr`.
    Read {
        /// First register.
        addr: u8,
        /// Number of bytes.
        count: u8,
    },
    /// Write `data` starting at `addr`.
    Write {
        /// First register.
        addr: u8,
        /// Bytes to write.
        data: &'a [u8],
    },
    /// Like `Write`, applied on [`Instruction::Action`].
    RegWrite {
        /// First register.
        addr: u8,
        /// Bytes to write.
        data: &'a [u8],
    },
    /// Apply held REG WRITEs.
    Action,
    /// Factory reset.
    Reset,
    /// Every servo in `ids` answers a READ of `count` bytes at `addr`, in that order.
    SyncRead {
        /// First register.
        addr: u8,
        /// Number of bytes.
        count: u8,
        /// Servos asked, in answer order.
        ids: &'a [u8],
    },
    /// Each servo writes its own `count` bytes at `addr`; `blocks` is `[id, data x count] x N`.
    SyncWrite {
        /// First register.
        addr: u8,
        /// Bytes per servo.
        count: u8,
        /// `[id, data...]` blocks of `count + 1` bytes.
        blocks: &'a [u8],
    },
}

impl<'a> Instruction<'a> {
    /// The meaning of an instruction packet.
    pub fn parse(packet: &'a Packet) -> Result<Self, InstructionError> {
        use instruction as i;
        let p = packet.params();
        let bad = InstructionError::BadParameters;
        Ok(match packet.code() {
            i::PING => Self::Ping,
            i::ACTION => Self::Action,
            i::RESET => Self::Reset,
            i::READ => match p {
                &[addr, count] => Self::Read { addr, count },
                _ => return Err(bad),
            },
            i::WRITE | i::REG_WRITE => {
                let (&addr, data) = p.split_first().ok_or(bad)?;
                if data.is_empty() {
                    return Err(bad);
                }
                if packet.code() == i::WRITE {
                    Self::Write { addr, data }
                } else {
                    Self::RegWrite { addr, data }
                }
            }
            i::SYNC_READ => match p {
                [addr, count, ids @ ..] => Self::SyncRead {
                    addr: *addr,
                    count: *count,
                    ids,
                },
                _ => return Err(bad),
            },
            i::SYNC_WRITE => match p {
                [addr, count, blocks @ ..]
                    if *count > 0 && blocks.len() % (*count as usize + 1) == 0 =>
                {
                    Self::SyncWrite {
                        addr: *addr,
                        count: *count,
                        blocks,
                    }
                }
                _ => return Err(bad),
            },
            other => return Err(InstructionError::UnknownInstruction(other)),
        })
    }

    /// For a SYNC WRITE, the data block addressed to servo `id`, if any.
    pub fn sync_write_data_for(&self, id: u8) -> Option<&'a [u8]> {
        match *self {
            Self::SyncWrite { count, blocks, .. } => blocks
                .chunks_exact(count as usize + 1)
                .find(|b| b.first() == Some(&id))
                .and_then(|b| b.get(1..)),
            _ => None,
        }
    }

    /// Builds the instruction packet addressed to `id`; `None` if it does not fit a packet.
    pub fn to_packet(&self, id: u8) -> Option<Packet> {
        use instruction as i;
        let mut params: Vec<u8, MAX_PARAMS> = Vec::new();
        let code = match *self {
            Self::Ping => i::PING,
            Self::Action => i::ACTION,
            Self::Reset => i::RESET,
            Self::Read { addr, count } => {
                params.extend_from_slice(&[addr, count]).ok()?;
                i::READ
            }
            Self::Write { addr, data } | Self::RegWrite { addr, data } => {
                params.push(addr).ok()?;
                params.extend_from_slice(data).ok()?;
                if matches!(self, Self::Write { .. }) {
                    i::WRITE
                } else {
                    i::REG_WRITE
                }
            }
            Self::SyncRead { addr, count, ids } => {
                params.extend_from_slice(&[addr, count]).ok()?;
                params.extend_from_slice(ids).ok()?;
                i::SYNC_READ
            }
            Self::SyncWrite {
                addr,
                count,
                blocks,
            } => {
                params.extend_from_slice(&[addr, count]).ok()?;
                params.extend_from_slice(blocks).ok()?;
                i::SYNC_WRITE
            }
        };
        Some(Packet { id, code, params })
    }
}

/// Builds the `[id, data...]` blocks of a SYNC WRITE.
#[derive(Clone, Debug)]
pub struct SyncWriteBuilder {
    addr: u8,
    count: u8,
    blocks: Vec<u8, { MAX_PARAMS - 2 }>,
}

impl SyncWriteBuilder {
    /// A SYNC WRITE of `count` bytes at `addr` to no servo yet.
    pub fn new(addr: u8, count: u8) -> Self {
        Self {
            addr,
            count,
            blocks: Vec::new(),
        }
    }

    /// Adds servo `id`'s data; `None` if `data` is not `count` bytes or the packet is full.
    pub fn push(&mut self, id: u8, data: &[u8]) -> Option<()> {
        if data.len() != self.count as usize
            || self.blocks.len() + data.len() + 1 > self.blocks.capacity()
        {
            return None;
        }
        self.blocks.push(id).ok()?;
        self.blocks.extend_from_slice(data).ok()
    }

    /// The broadcast instruction packet.
    pub fn to_packet(&self) -> Option<Packet> {
        Instruction::SyncWrite {
            addr: self.addr,
            count: self.count,
            blocks: &self.blocks,
        }
        .to_packet(BROADCAST_ID)
    }
}

/// Streaming decoder of servo packets (either direction).
///
/// Feed every byte of the wire with [`push`](Self::push); each packet with a valid checksum is
/// returned once. Host frames and noise on the wire are skipped; a candidate with a bad
/// checksum or impossible LEN is dropped and the scan restarts at the byte after its first `FF`.
/// Drain [`next_packet`](Self::next_packet) after every `Some`, as for
/// [`FrameDecoder`](crate::FrameDecoder).
#[derive(Clone, Debug)]
pub struct PacketDecoder {
    scanner: Scanner<MAX_PACKET_BYTES>,
}

impl Default for PacketDecoder {
    fn default() -> Self {
        Self::new()
    }
}

/// The servo-packet format for the [`Scanner`].
struct ServoPackets;

/// Whether `len` is a possible LEN byte of a servo packet.
fn valid_len(len: u8) -> bool {
    (2..=MAX_PARAMS as u8 + 2).contains(&len)
}

impl Format for ServoPackets {
    const HEADER: u8 = HEADER;

    fn scan(b: &[u8]) -> Scan {
        match (b.first(), b.get(1), b.get(2), b.get(3)) {
            (None, ..) => Scan::NeedMore,
            (Some(&h), ..) if h != HEADER => Scan::Reject,
            (_, None, ..) => Scan::NeedMore,
            (_, Some(&h), ..) if h != HEADER => Scan::Reject,
            (_, _, None, _) => Scan::NeedMore,
            // FF FF FF: the first FF was noise (0xFF is never an id).
            (_, _, Some(&id), _) if id == HEADER => Scan::Reject,
            (_, _, _, None) => Scan::NeedMore,
            (_, _, _, Some(&len)) if !valid_len(len) => Scan::Reject,
            (_, _, Some(&id), Some(&len)) => {
                let n = 4 + len as usize;
                let (Some(&code), Some(params), Some(&chk)) =
                    (b.get(4), b.get(5..n - 1), b.get(n - 1))
                else {
                    return Scan::NeedMore;
                };
                if checksum(id, len, code, params) == chk {
                    Scan::Complete(n)
                } else {
                    Scan::BadChecksum
                }
            }
        }
    }

    fn missing(b: &[u8]) -> usize {
        match b {
            [HEADER, HEADER, id, len, ..] if *id != HEADER && valid_len(*len) => {
                (4 + *len as usize).saturating_sub(b.len())
            }
            _ => 1,
        }
    }
}

/// The packet in `bytes`, a complete `FF FF ID LEN CODE PARAMS CHK` with a valid checksum.
fn packet_from(bytes: &[u8]) -> Option<Packet> {
    let [_, _, id, _, code, rest @ ..] = bytes else {
        return None;
    };
    let (_checksum, params) = rest.split_last()?;
    Packet::new(*id, *code, params)
}

impl PacketDecoder {
    /// An empty decoder.
    pub const fn new() -> Self {
        Self {
            scanner: Scanner::new(),
        }
    }

    /// Appends one received byte; returns the packet it completes, if any.
    pub fn push(&mut self, byte: u8) -> Option<Packet> {
        self.scanner.push(byte);
        self.next_packet()
    }

    /// Feeds every byte of `bytes`, calling `on_packet` with each packet found, in order.
    ///
    /// Same result as [`push`](Self::push)ing byte by byte and draining, but faster: while idle
    /// it skips straight to the next `FF`, and once a candidate's LEN is known it copies the
    /// rest of the candidate in one go.
    pub fn feed(&mut self, bytes: &[u8], on_packet: impl FnMut(Packet)) {
        self.scanner
            .feed::<ServoPackets, _>(bytes, packet_from, on_packet);
    }

    /// Returns the next complete packet already in the buffer, if any.
    pub fn next_packet(&mut self) -> Option<Packet> {
        self.scanner.next::<ServoPackets, _>(packet_from)
    }

    /// Tells the decoder the wire went quiet: a packet still incomplete was cut short. Returns a
    /// complete packet uncovered by the rescan, if any (drain as after [`push`](Self::push)).
    pub fn on_quiet_line(&mut self) -> Option<Packet> {
        self.scanner.on_quiet_line();
        self.next_packet()
    }

    /// True while the decoder holds the start of a packet that is not complete yet.
    pub fn has_partial(&self) -> bool {
        self.scanner.has_partial()
    }

    /// Bytes held: the candidate in progress and whatever was received after its start.
    pub(crate) fn held(&self) -> usize {
        self.scanner.len()
    }

    /// Forgets the first `n` bytes held (they were a host frame's data that looked like the
    /// start of a packet); the rest is scanned again.
    pub(crate) fn discard(&mut self, n: usize) {
        self.scanner.discard(n);
    }

    /// Number of candidates dropped for a wrong checksum (corrupted replies). Wraps.
    pub fn checksum_errors(&self) -> u32 {
        self.scanner.bad_checksums()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ping_packet_matches_the_feetech_example() {
        // FF FF 01 02 01 FB: ping servo 1 (Feetech manual).
        let p = Instruction::Ping.to_packet(1).unwrap();
        assert_eq!(
            p.to_bytes().as_slice(),
            &[0xFF, 0xFF, 0x01, 0x02, 0x01, 0xFB]
        );
    }

    #[test]
    fn read_position_packet() {
        // FF FF 01 04 02 38 02 BE: read 2 bytes at 56 from servo 1.
        let p = Instruction::Read { addr: 56, count: 2 }
            .to_packet(1)
            .unwrap();
        assert_eq!(
            p.to_bytes().as_slice(),
            &[0xFF, 0xFF, 0x01, 0x04, 0x02, 0x38, 0x02, 0xBE]
        );
    }

    #[test]
    fn decoder_round_trips_and_skips_host_frames() {
        let status = Packet::new(3, 0, &[0x00, 0x08, 0x00, 0x00]).unwrap();
        let mut wire = std::vec![0xFE, 0xFE, 0x02, 0x20, 0xFA, 0xFF];
        wire.extend_from_slice(&status.to_bytes());
        let mut out = std::vec::Vec::new();
        PacketDecoder::new().feed(&wire, |p| out.push(p));
        assert_eq!(out, [status]);
    }

    #[test]
    fn bad_checksum_is_counted_and_dropped() {
        let mut bytes = Instruction::Ping.to_packet(1).unwrap().to_bytes();
        let last = bytes.len() - 1;
        bytes[last] ^= 0x55;
        let mut d = PacketDecoder::new();
        let mut out = std::vec::Vec::new();
        d.feed(&bytes, |p| out.push(p));
        assert!(out.is_empty());
        assert_eq!(d.checksum_errors(), 1);
    }

    #[test]
    fn sign_magnitude_round_trip() {
        assert_eq!(sign_magnitude(0x8005, 15), -5);
        assert_eq!(sign_magnitude(0x0405, 10), -5);
        assert_eq!(to_sign_magnitude(-5, 15), 0x8005);
        assert_eq!(to_sign_magnitude(-5, 10), 0x0405);
        for v in [-2047i16, -1, 0, 1, 2047] {
            assert_eq!(sign_magnitude(to_sign_magnitude(v, 11), 11), v);
        }
    }

    #[test]
    fn sync_write_builder_and_lookup() {
        let mut b = SyncWriteBuilder::new(reg::MOVE_BLOCK, 7);
        b.push(1, &[0, 0, 8, 0, 0, 0, 0]).unwrap();
        b.push(2, &[1, 2, 3, 4, 5, 6, 7]).unwrap();
        assert!(b.push(3, &[1]).is_none());
        let packet = b.to_packet().unwrap();
        assert_eq!(packet.id(), BROADCAST_ID);
        let instr = Instruction::parse(&packet).unwrap();
        assert_eq!(
            instr.sync_write_data_for(2),
            Some(&[1, 2, 3, 4, 5, 6, 7][..])
        );
        assert_eq!(instr.sync_write_data_for(5), None);
    }

    #[test]
    fn parse_rejects_bad_layouts() {
        let p = Packet::new(1, instruction::READ, &[56]).unwrap();
        assert_eq!(Instruction::parse(&p), Err(InstructionError::BadParameters));
        let p = Packet::new(1, 0x77, &[]).unwrap();
        assert_eq!(
            Instruction::parse(&p),
            Err(InstructionError::UnknownInstruction(0x77))
        );
    }
}

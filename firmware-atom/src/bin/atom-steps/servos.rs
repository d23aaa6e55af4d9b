//! Six joint servos and the gripper inside the image: the Atom's bus port answers as the
//! servos would, so the Atom's real loop runs its state refresh, moves and backups on the chip
//! with nothing attached.
//!
//! Each servo has a control table, answers PING, READ and SYNC READ at once (no wire time: the
//! passes are what is measured), takes WRITE, REG WRITE + ACTION and SYNC WRITE, and runs its
//! shaft towards the goal at the goal speed, so the Atom's readings never jump. The bus echoes
//! what the Atom sends, as the half-duplex wire does.

use heapless::Deque;
use protocol_core::BytePort;
use protocol_core::servo::{BROADCAST_ID, Packet, PacketDecoder, instruction, reg};

/// Servo ids on the bus: joints 1..6 and the gripper.
const IDS: core::ops::RangeInclusive<u8> = 1..=7;
/// Steps per second when the goal speed register is 0 (the servo's own top speed).
const TOP_SPEED: i64 = 3_000;
/// Bytes waiting for the Atom to read: its own echo and the answers.
const RX_BYTES: usize = 1_024;

/// One servo: its control table and where its shaft is.
struct Servo {
    id: u8,
    table: [u8; reg::TABLE_SIZE],
    /// Shaft position, steps times 1000 (so slow speeds still move every pass).
    position_milli: i64,
    /// A REG WRITE waiting for ACTION: address and data.
    registered: Option<(u8, heapless::Vec<u8, 64>)>,
}

impl Servo {
    fn new(id: u8) -> Self {
        let mut table = [0u8; reg::TABLE_SIZE];
        let mut put = |addr: u8, bytes: &[u8]| {
            for (i, b) in bytes.iter().enumerate() {
                if let Some(slot) = table.get_mut(usize::from(addr) + i) {
                    *slot = *b;
                }
            }
        };
        put(reg::FIRMWARE_MAJOR, &[3, 10]);
        put(reg::MODEL, &9u16.to_le_bytes());
        put(reg::ID, &[id]);
        put(reg::MAX_POSITION, &4095u16.to_le_bytes());
        put(reg::MAX_TEMPERATURE, &[70]);
        put(reg::MAX_VOLTAGE, &[140]);
        put(reg::MIN_VOLTAGE, &[40]);
        put(reg::MAX_TORQUE, &1000u16.to_le_bytes());
        put(reg::P_COEFFICIENT, &[32, 32, 0]);
        put(reg::TORQUE_LIMIT, &1000u16.to_le_bytes());
        put(reg::GOAL_POSITION, &2048u16.to_le_bytes());
        put(reg::PRESENT_POSITION, &2048u16.to_le_bytes());
        put(reg::PRESENT_VOLTAGE, &[120]);
        put(reg::PRESENT_TEMPERATURE, &[30]);
        Self {
            id,
            table,
            position_milli: 2048 * 1000,
            registered: None,
        }
    }

    fn u16_at(&self, addr: u8) -> u16 {
        let at = |i: u8| self.table.get(usize::from(addr + i)).copied().unwrap_or(0);
        u16::from_le_bytes([at(0), at(1)])
    }

    fn write(&mut self, addr: u8, data: &[u8]) {
        for (i, b) in data.iter().enumerate() {
            if let Some(slot) = self.table.get_mut(usize::from(addr) + i) {
                *slot = *b;
            }
        }
    }

    /// The shaft `elapsed_us` further towards its goal (only with torque on).
    fn run(&mut self, elapsed_us: u64) {
        let goal = i64::from(self.u16_at(reg::GOAL_POSITION) & 0x0FFF) * 1000;
        let torque = self
            .table
            .get(usize::from(reg::TORQUE_ENABLE))
            .copied()
            .unwrap_or(0)
            != 0;
        let speed = match i64::from(self.u16_at(reg::GOAL_SPEED) & 0x7FFF) {
            0 => TOP_SPEED,
            s => s.min(TOP_SPEED),
        };
        let step = speed * i64::try_from(elapsed_us).unwrap_or(i64::MAX / 4_000) / 1000;
        let before = self.position_milli;
        if torque {
            self.position_milli += (goal - before).clamp(-step, step);
        }
        let moved = self.position_milli != before;
        let present = u16::try_from(self.position_milli / 1000).unwrap_or(0);
        self.write(reg::PRESENT_POSITION, &present.to_le_bytes());
        let speed_now = if moved { speed as u16 } else { 0 };
        self.write(reg::PRESENT_SPEED, &speed_now.to_le_bytes());
        self.write(reg::MOVING, &[u8::from(moved)]);
    }
}

/// The bus as the Atom's UART sees it, with the servos on it.
pub struct ServoBus {
    servos: [Servo; 7],
    decoder: PacketDecoder,
    rx: Deque<u8, RX_BYTES>,
    ran_us: u64,
}

impl ServoBus {
    /// Servos at their centre, torque off, as after power-up.
    pub fn new() -> Self {
        Self {
            servos: core::array::from_fn(|i| Servo::new(i as u8 + 1)),
            decoder: PacketDecoder::new(),
            rx: Deque::new(),
            ran_us: 0,
        }
    }

    /// Every shaft moved on to `now_us`.
    pub fn run_to(&mut self, now_us: u64) {
        let elapsed = now_us.saturating_sub(self.ran_us);
        self.ran_us = now_us;
        for servo in &mut self.servos {
            servo.run(elapsed);
        }
    }

    fn servo(&mut self, id: u8) -> Option<&mut Servo> {
        self.servos.iter_mut().find(|s| s.id == id)
    }

    fn answer(&mut self, id: u8, params: &[u8]) {
        if let Some(packet) = Packet::new(id, 0, params) {
            for b in packet.to_bytes() {
                self.rx.push_back(b).ok();
            }
        }
    }

    fn read_answer(&mut self, id: u8, addr: u8, len: u8) {
        let Some(servo) = self.servo(id) else { return };
        let from = usize::from(addr);
        let Some(data) = servo.table.get(from..from + usize::from(len)) else {
            return;
        };
        let mut params = heapless::Vec::<u8, 96>::new();
        params.extend_from_slice(data).ok();
        self.answer(id, &params);
    }

    fn on_packet(&mut self, packet: &Packet) {
        let (id, params) = (packet.id(), packet.params());
        let broadcast = id == BROADCAST_ID;
        if !broadcast && !IDS.contains(&id) {
            return;
        }
        match packet.code() {
            instruction::PING if !broadcast => self.answer(id, &[]),
            instruction::READ if !broadcast => {
                if let [addr, len] = params {
                    self.read_answer(id, *addr, *len);
                }
            }
            instruction::WRITE => {
                if let [addr, data @ ..] = params {
                    for servo in &mut self.servos {
                        if broadcast || servo.id == id {
                            servo.write(*addr, data);
                        }
                    }
                    if !broadcast {
                        self.answer(id, &[]);
                    }
                }
            }
            instruction::REG_WRITE => {
                if let ([addr, data @ ..], Some(servo)) = (params, self.servo(id)) {
                    let mut kept = heapless::Vec::new();
                    kept.extend_from_slice(data).ok();
                    servo.registered = Some((*addr, kept));
                    self.answer(id, &[]);
                }
            }
            instruction::ACTION => {
                for servo in &mut self.servos {
                    if let Some((addr, data)) = servo.registered.take() {
                        servo.write(addr, &data);
                    }
                }
            }
            instruction::SYNC_READ => {
                if let [addr, len, ids @ ..] = params {
                    for &one in ids {
                        self.read_answer(one, *addr, *len);
                    }
                }
            }
            instruction::SYNC_WRITE => {
                if let [addr, len, rest @ ..] = params {
                    let each = usize::from(*len) + 1;
                    for chunk in rest.chunks(each.max(1)) {
                        if let [one, data @ ..] = chunk
                            && let Some(servo) = self.servo(*one)
                        {
                            servo.write(*addr, data);
                        }
                    }
                }
            }
            instruction::RESET if !broadcast => self.answer(id, &[]),
            _ => {}
        }
    }
}

impl BytePort for ServoBus {
    fn read_byte(&mut self) -> Option<u8> {
        self.rx.pop_front()
    }

    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            // The wire echoes every byte to its sender.
            self.rx.push_back(b).ok();
        }
        for &b in bytes {
            let mut found = self.decoder.push(b);
            while let Some(packet) = found {
                self.on_packet(&packet);
                found = self.decoder.next_packet();
            }
        }
    }

    fn tx_idle(&self) -> bool {
        true
    }
}

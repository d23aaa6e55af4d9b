//! The whole virtual arm under virtual time: the real Basic and Atom firmware libraries, the
//! shared bus, seven simulated servos, and the USB serial links of both boards.

use firmware_atom::collision::Collision;
use firmware_atom::{Atom, AtomConfig, RecordingIo};
use firmware_basic::clients::CLIENT_RX_BYTES;
use firmware_basic::teach::{Teach, TeachStatus};
use firmware_basic::wifi::WifiStore;
use firmware_basic::{Basic, BasicConfig, BasicIo, Buttons, NetworkClients, Programmed};
use protocol_core::command::{Reply, ReplyError, Request};
use protocol_core::timing::{HOST_BAUD, HOST_REPLY_DEADLINE_US};
use protocol_core::units::{Centideg, Steps};
use protocol_core::{Frame, FrameDecoder};

use super::basic_flash::BasicFlashStore;
use super::contact::{self, Obstacle};
use super::flash_timing::{FlashTiming, FlashWork};
use super::hops::{BasicMark, HopTrace};
use super::reply_faults::ReplyFault;
use super::servo::SimServo;
use super::wire::{Bus, HeardByte, SerialLine, SerialPort, StationId};
use sim_hw::ServoChain;

/// Longest virtual time between two polls of the Basic and the Atom, in ns: one byte time on
/// the bus, so no station ever misses a byte-time boundary by more than that.
pub const POLL_PERIOD_NS: u64 = 10_000;

/// Ids of the simulated servos: joints 1..6 and the gripper (7).
pub const SERVO_IDS: [u8; 7] = [1, 2, 3, 4, 5, 6, 7];

/// How the virtual arm is built. `Default` is the real arm: Basic and Atom both on the bus,
/// both hearing their own echo (TX and RX tied), servos at 2048 (all joints at 0 degrees).
#[derive(Clone, Copy, Debug)]
pub struct RobotConfig {
    /// Whether the Atom receives its own bus transmissions.
    pub atom_hears_echo: bool,
    /// Whether the Basic receives its own bus transmissions.
    pub basic_hears_echo: bool,
    /// Whether the Basic is present. Without it the host talks to the Atom's USB port only.
    pub with_basic: bool,
    /// Seed of the simulated randomness (what collisions turn bytes into).
    pub seed: u64,
    /// The Atom firmware's configuration.
    pub atom: AtomConfig,
    /// The Basic firmware's configuration.
    pub basic: BasicConfig,
    /// Encoder position of every servo at power-up, in steps (2048 = 0 degrees).
    pub initial_position_steps: u16,
    /// Time one pass of the Atom's main loop takes, in us: the Atom is polled only this often
    /// (bytes wait in its UART meanwhile). 0 (the default) polls it whenever anything happens
    /// and at least every [`POLL_PERIOD_NS`], i.e. an infinitely fast board.
    pub atom_loop_us: u64,
    /// Like [`RobotConfig::atom_loop_us`] for the Basic.
    pub basic_loop_us: u64,
    /// How long a board stands still for its flash ([`FlashTiming`], typical by default).
    pub flash_timing: FlashTiming,
    /// A program the Basic runs beside its transponder (`firmware_basic::program`); `None`,
    /// the shipped Basic, runs none.
    pub basic_program: Option<BasicProgram>,
}

/// A program of the Basic's (`firmware_basic::program`), as the board image `basic-teach`
/// runs it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BasicProgram {
    /// Teach and play (`firmware_basic::teach`): A records the arm moved by hand, B plays it
    /// back, C stops.
    Teach,
}

/// The Basic's firmware: the transponder alone, or with a program.
#[derive(Debug)]
enum BasicFirmware {
    Transponder(Box<Basic>),
    Teach(Box<Programmed<Teach>>),
}

impl BasicFirmware {
    fn new(config: BasicConfig, program: Option<BasicProgram>) -> Self {
        match program {
            None => Self::Transponder(Box::new(Basic::new(config))),
            Some(BasicProgram::Teach) => {
                Self::Teach(Box::new(Programmed::new(config, Teach::new())))
            }
        }
    }

    fn basic(&self) -> &Basic {
        match self {
            Self::Transponder(basic) => basic,
            Self::Teach(programmed) => programmed.basic(),
        }
    }

    fn basic_mut(&mut self) -> &mut Basic {
        match self {
            Self::Transponder(basic) => basic,
            Self::Teach(programmed) => programmed.basic_mut(),
        }
    }

    fn poll<U: protocol_core::BytePort, B: protocol_core::BytePort, I: BasicIo>(
        &mut self,
        clients: &mut NetworkClients,
        now_us: u64,
        usb: &mut U,
        bus: &mut B,
        io: &mut I,
    ) {
        match self {
            Self::Transponder(basic) => clients.poll_basic(basic, now_us, usb, bus, io),
            Self::Teach(programmed) => programmed.poll(now_us, &mut clients.ports(usb), bus, io),
        }
    }
}

impl Default for RobotConfig {
    fn default() -> Self {
        Self {
            atom_hears_echo: true,
            basic_hears_echo: true,
            with_basic: true,
            seed: 0x6d79_436f_626f_7421,
            atom: AtomConfig {
                powered_at_boot: true,
                ..AtomConfig::default()
            },
            basic: BasicConfig::default(),
            initial_position_steps: 2048,
            atom_loop_us: 0,
            basic_loop_us: 0,
            flash_timing: FlashTiming::Typical,
            basic_program: None,
        }
    }
}

/// Microseconds a board stood still for the flash work done between `before` and `after`.
fn flash_busy_us(before: Option<FlashWork>, after: Option<FlashWork>, timing: FlashTiming) -> u64 {
    match (before, after) {
        (Some(before), Some(after)) => after.busy_us_since(before, timing),
        _ => 0,
    }
}

/// A board whose last pass did flash work stands still until `until_ns` (if that is after
/// `now_ns`): no pass, only its UARTs' FIFOs take bytes, and what it wrote goes out then.
fn stand_still_until(
    (main_loop, station, usb): (&mut BoardLoop, StationId, &mut UsbLink),
    bus: &mut Bus,
    now_ns: u64,
    until_ns: u64,
) {
    if until_ns > now_ns {
        main_loop.stand_still_until(until_ns);
        bus.freeze_station(station, until_ns);
        usb.stand_still_until(until_ns);
    }
}

/// The Basic's pins and sensors in the simulation: outputs remember their level, inputs and
/// the ToF distance are set by tests.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SimBasicIo {
    /// Levels of outputs GPIO2 and GPIO5 (in that order).
    pub outputs: [bool; 2],
    /// Levels of inputs GPIO35 and GPIO36 (in that order).
    pub inputs: [bool; 2],
    /// What the ToF sensor measures, in mm; `None` = no sensor.
    pub tof_mm: Option<u16>,
    /// Front buttons held.
    pub buttons: Buttons,
}

impl BasicIo for SimBasicIo {
    fn set_output(&mut self, pin: u8, high: bool) -> bool {
        let slot = match pin {
            2 => self.outputs.get_mut(0),
            5 => self.outputs.get_mut(1),
            _ => None,
        };
        slot.map(|level| *level = high).is_some()
    }

    fn read_input(&mut self, pin: u8) -> Option<bool> {
        match pin {
            35 => self.inputs.first().copied(),
            36 => self.inputs.get(1).copied(),
            _ => None,
        }
    }

    fn tof_distance_mm(&mut self) -> Option<u16> {
        self.tof_mm
    }

    fn buttons(&mut self) -> Buttons {
        self.buttons
    }
}

/// What the simulated Basic's firmware is lent as its board: the pins and its flash.
struct SimBoardIo<'a> {
    io: &'a mut SimBasicIo,
    flash: &'a mut BasicFlashStore,
}

impl BasicIo for SimBoardIo<'_> {
    fn set_output(&mut self, pin: u8, high: bool) -> bool {
        self.io.set_output(pin, high)
    }

    fn read_input(&mut self, pin: u8) -> Option<bool> {
        self.io.read_input(pin)
    }

    fn tof_distance_mm(&mut self) -> Option<u16> {
        self.io.tof_distance_mm()
    }

    fn buttons(&mut self) -> Buttons {
        self.io.buttons()
    }

    fn wifi_store(&mut self) -> Option<&mut dyn WifiStore> {
        Some(self.flash)
    }

    fn dialect_store(&mut self) -> Option<&mut dyn firmware_basic::DialectStore> {
        Some(self.flash)
    }
}

/// When a board's main loop runs next (see [`RobotConfig::atom_loop_us`]).
#[derive(Clone, Copy, Debug)]
struct BoardLoop {
    period_ns: u64,
    next_ns: u64,
    /// While its flash keeps the board standing still: when it goes on.
    still_until_ns: Option<u64>,
}

impl BoardLoop {
    fn new(period_us: u64) -> Self {
        Self {
            period_ns: period_us.saturating_mul(1_000),
            next_ns: 0,
            still_until_ns: None,
        }
    }

    /// Whether the board runs at `now_ns`; if so, schedules its next pass.
    fn runs_at(&mut self, now_ns: u64) -> bool {
        if let Some(until) = self.still_until_ns {
            if now_ns < until {
                return false;
            }
            self.still_until_ns = None;
        }
        let due = now_ns >= self.next_ns;
        if due {
            self.next_ns = now_ns + self.period_ns;
        }
        due
    }

    /// The board stands still (its flash is erasing or writing) until `until_ns`.
    fn stand_still_until(&mut self, until_ns: u64) {
        self.still_until_ns = Some(until_ns);
    }

    /// When the next pass is due, for a board that does not run on every event or stands
    /// still.
    fn next_event_ns(&self) -> Option<u64> {
        let periodic = (self.period_ns > 0).then_some(self.next_ns);
        match (periodic, self.still_until_ns) {
            (Some(a), Some(b)) => Some(a.max(b)),
            (a, b) => b.or(a),
        }
    }
}

/// A board's USB serial: what the host sent to it and what it sends to the host.
#[derive(Clone, Debug)]
struct UsbLink {
    to_board: SerialLine,
    to_host: SerialLine,
}

impl UsbLink {
    fn new() -> Self {
        Self {
            to_board: SerialLine::new(HOST_BAUD),
            to_host: SerialLine::new(HOST_BAUD),
        }
    }

    fn deliver(&mut self, now_ns: u64) {
        self.to_board.deliver(now_ns);
        self.to_host.deliver(now_ns);
    }

    fn next_event_ns(&self) -> Option<u64> {
        match (self.to_board.next_event_ns(), self.to_host.next_event_ns()) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
    }

    /// The board stands still until `until_ns`: its UART takes only its FIFO's worth of the
    /// host's bytes, and what it wrote goes out then.
    fn stand_still_until(&mut self, until_ns: u64) {
        self.to_board.freeze_receiver(until_ns);
        self.to_host.hold_sending_until(until_ns);
    }

    fn board_port(&mut self, now_ns: u64) -> SerialPort<'_> {
        SerialPort {
            rx: &mut self.to_board,
            tx: &mut self.to_host,
            now_ns,
        }
    }
}

/// Bytes a network client may have on their way to the Basic at once; a client that sends more
/// waits (TCP flow control: [`VirtualRobot::link_room`]). The Basic library's own buffer
/// (`firmware_basic::clients`), as on the board.
pub const NET_BUFFER_BYTES: usize = CLIENT_RX_BYTES;

struct BasicBoard {
    firmware: BasicFirmware,
    config: BasicConfig,
    program: Option<BasicProgram>,
    main_loop: BoardLoop,
    /// When the firmware last started, in ns: its clock starts at 0 there.
    boot_ns: u64,
    station: StationId,
    usb: UsbLink,
    /// The network clients connected now: the Basic library's own client handling, with no
    /// wire time (what one side writes, the other can read at once).
    clients: NetworkClients,
    io: SimBasicIo,
    /// Where its Wi-Fi settings live.
    flash: BasicFlashStore,
}

/// Why [`VirtualRobot::ask`] got no usable answer.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum AskError {
    /// No complete frame came back within pymycobot's reply deadline (0.5 s).
    NoReply,
    /// A frame came back for another command (pymycobot ignores it).
    WrongCommand {
        /// The CMD byte of the frame that came back.
        cmd: u8,
    },
    /// The frame had the right command but not the shape the request expects.
    BadReply(ReplyError),
}

/// Which link a host talks to the arm on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HostLink {
    /// The Basic's USB serial (the normal way; falls silent without a Basic).
    Basic,
    /// The Atom's own USB serial (direct host link).
    AtomUsb,
    /// A network client of the Basic (TCP, like its Wi-Fi server): one of its host links, from
    /// [`VirtualRobot::connect`].
    Network(NetClient),
}

/// One network client of the Basic, from [`VirtualRobot::connect`]; never reused, so a client
/// that has gone (or lost its link when the Basic restarted) reaches nobody.
pub use firmware_basic::NetClient;

/// The virtual myCobot 280 M5. See the [simulation overview](crate::sim).
///
/// Time only moves in [`VirtualRobot::run_until`] / [`VirtualRobot::run_for`], as fast as the
/// host computes it. A real-time driver calls `run_until(wall_clock_us)` in a loop.
pub struct VirtualRobot {
    now_ns: u64,
    bus: Bus,
    basic: Option<BasicBoard>,
    atom: Atom,
    atom_config: AtomConfig,
    /// When the Atom firmware last started, in ns: its clock starts at 0 there.
    atom_boot_ns: u64,
    atom_loop: BoardLoop,
    atom_station: StationId,
    atom_usb: UsbLink,
    atom_io: RecordingIo,
    servos: ServoChain,
    heard: Vec<HeardByte>,
    noise_station: StationId,
    next_poll_ns: u64,
    /// Every collision the Atom detected, with the virtual time it was first seen (ns).
    collisions: Vec<(u64, Collision)>,
    /// How long a board stands still for its flash.
    flash_timing: FlashTiming,
    /// The Basic's marks while hop tracing is on ([`VirtualRobot::set_hop_tracing`]).
    basic_marks: Option<BasicMarks>,
}

/// The Basic's marks so far, and its counts of host frames and forwarded replies after its
/// last poll (a mark is a count that grew).
#[derive(Debug, Default)]
struct BasicMarks {
    marks: Vec<(u64, BasicMark)>,
    host_frames: u32,
    replies: u32,
}

impl VirtualRobot {
    /// A robot just switched on at time 0: firmware booting, every servo at
    /// `config.initial_position_steps`.
    pub fn new(config: RobotConfig) -> Self {
        let mut bus = Bus::mycobot(config.seed);
        let basic = config.with_basic.then(|| BasicBoard {
            firmware: BasicFirmware::new(config.basic, config.basic_program),
            config: config.basic,
            program: config.basic_program,
            main_loop: BoardLoop::new(config.basic_loop_us),
            boot_ns: 0,
            station: bus.attach(config.basic_hears_echo),
            usb: UsbLink::new(),
            clients: NetworkClients::new(),
            io: SimBasicIo::default(),
            flash: BasicFlashStore::in_memory(),
        });
        let atom_station = bus.attach(config.atom_hears_echo);
        let mut servos = ServoChain::new();
        for &id in &SERVO_IDS {
            servos.attach(&mut bus, SimServo::new(id, config.initial_position_steps));
        }
        let noise_station = bus.attach_transmitter();
        bus.set_tap(true);
        Self {
            now_ns: 0,
            bus,
            basic,
            atom: Atom::new(config.atom),
            atom_config: config.atom,
            atom_boot_ns: 0,
            atom_loop: BoardLoop::new(config.atom_loop_us),
            atom_station,
            atom_usb: UsbLink::new(),
            atom_io: RecordingIo::default(),
            servos,
            heard: Vec::new(),
            noise_station,
            next_poll_ns: 0,
            collisions: Vec::new(),
            flash_timing: config.flash_timing,
            basic_marks: None,
        }
    }

    /// Starts (or stops) tracing every byte on the bus and on the Basic's USB serial, both
    /// ways, and the polls in which the Basic took a host frame or forwarded a reply: what
    /// [`HopTrace::round_trips`] cuts into hops. Off by default.
    pub fn set_hop_tracing(&mut self, on: bool) {
        self.bus.set_tracing(on);
        if let Some(basic) = self.basic.as_mut() {
            basic.usb.to_board.set_tracing(on);
            basic.usb.to_host.set_tracing(on);
        }
        self.basic_marks = on.then(|| {
            let status = self.basic().map(Basic::status).unwrap_or_default();
            BasicMarks {
                marks: Vec::new(),
                host_frames: status.host_frames,
                replies: status.replies_forwarded,
            }
        });
    }

    /// What was traced since hop tracing began or the last call ([`VirtualRobot::set_hop_tracing`]).
    pub fn take_hop_trace(&mut self) -> HopTrace {
        let (to_basic, to_host) = self
            .basic
            .as_mut()
            .map(|b| (b.usb.to_board.take_trace(), b.usb.to_host.take_trace()))
            .unwrap_or_default();
        HopTrace {
            bus: self.bus.take_trace(),
            to_basic,
            to_host,
            basic_marks: self
                .basic_marks
                .as_mut()
                .map(|m| std::mem::take(&mut m.marks))
                .unwrap_or_default(),
        }
    }

    /// Notes what the Basic's poll at `now_ns` did, while hop tracing is on.
    fn mark_basic(&mut self, now_ns: u64) {
        let (Some(m), Some(basic)) = (self.basic_marks.as_mut(), self.basic.as_ref()) else {
            return;
        };
        let status = basic.firmware.basic().status();
        if status.host_frames != m.host_frames {
            m.marks.push((now_ns, BasicMark::HostFrame));
        }
        if status.replies_forwarded != m.replies {
            m.marks.push((now_ns, BasicMark::ReplyForwarded));
        }
        (m.host_frames, m.replies) = (status.host_frames, status.replies_forwarded);
    }

    /// This robot with its Basic's flash (its Wi-Fi settings) in `flash`, e.g. kept in a file
    /// ([`BasicFlashStore::open`]); by default it is an erased flash in RAM. The Basic loads its
    /// settings when it boots: call this before the robot runs (or reset the Basic after).
    pub fn with_basic_flash(mut self, flash: BasicFlashStore) -> Self {
        if let Some(basic) = self.basic.as_mut() {
            basic.flash = flash;
        }
        self
    }

    /// The Basic's flash, to make it fail or look at it; `None` without a Basic.
    pub fn basic_flash_mut(&mut self) -> Option<&mut BasicFlashStore> {
        self.basic.as_mut().map(|b| &mut b.flash)
    }

    /// Virtual time since power-up, in microseconds.
    pub fn now_us(&self) -> u64 {
        self.now_ns / 1_000
    }

    /// Virtual time since power-up, in nanoseconds.
    pub fn now_ns(&self) -> u64 {
        self.now_ns
    }

    /// Sends `bytes` from the host into the Basic's USB serial; they arrive at 115200 baud.
    /// Dropped if the robot has no Basic.
    pub fn host_write(&mut self, bytes: &[u8]) {
        self.link_write(HostLink::Basic, bytes);
    }

    /// Appends to `out` the bytes the Basic sent to the host that have fully arrived.
    pub fn host_read(&mut self, out: &mut Vec<u8>) {
        self.link_read(HostLink::Basic, out);
    }

    /// Sends `bytes` from a host into the Atom's own USB serial.
    pub fn atom_usb_write(&mut self, bytes: &[u8]) {
        self.link_write(HostLink::AtomUsb, bytes);
    }

    /// Appends to `out` the bytes the Atom sent on its own USB serial that have arrived.
    pub fn atom_usb_read(&mut self, out: &mut Vec<u8>) {
        self.link_read(HostLink::AtomUsb, out);
    }

    /// Sends `bytes` from a host into `link`. On a network link, what does not fit in
    /// [`VirtualRobot::link_room`] is dropped.
    pub fn link_write(&mut self, link: HostLink, bytes: &[u8]) {
        let now = self.now_ns;
        if let Some(usb) = self.usb_mut(link) {
            usb.to_board.send(now, bytes);
        } else if let Some((basic, client)) = self.net_mut(link) {
            basic.clients.receive(client, bytes);
        }
    }

    /// How many bytes `link` takes now: a serial line queues everything (its wire time paces
    /// it), a network link at most [`NET_BUFFER_BYTES`] waiting for the Basic.
    pub fn link_room(&self, link: HostLink) -> usize {
        match link {
            HostLink::Network(client) => self.basic.as_ref().map_or(0, |b| b.clients.room(client)),
            HostLink::Basic | HostLink::AtomUsb => usize::MAX,
        }
    }

    /// Appends to `out` the bytes that arrived at the host on `link`.
    pub fn link_read(&mut self, link: HostLink, out: &mut Vec<u8>) {
        if let Some(usb) = self.usb_mut(link) {
            usb.to_host.receive_all(out);
        } else if let Some((basic, client)) = self.net_mut(link) {
            let mut chunk = [0u8; 256];
            loop {
                let n = basic.clients.transmit(client, &mut chunk);
                let Some(bytes) = chunk.get(..n).filter(|b| !b.is_empty()) else {
                    break;
                };
                out.extend_from_slice(bytes);
            }
        }
    }

    /// When (virtual ns) the next byte on its way to the host on `link` arrives, if one is on
    /// the wire: a serial link's; a network client's bytes arrive at once, so never.
    pub fn link_next_arrival_ns(&self, link: HostLink) -> Option<u64> {
        let usb = match link {
            HostLink::Basic => &self.basic.as_ref()?.usb,
            HostLink::AtomUsb => &self.atom_usb,
            HostLink::Network(_) => return None,
        };
        usb.to_host.next_event_ns()
    }

    /// Takes the next byte that arrived at the host on `link`.
    fn link_receive(&mut self, link: HostLink) -> Option<u8> {
        if let Some(usb) = self.usb_mut(link) {
            return usb.to_host.receive();
        }
        let (basic, client) = self.net_mut(link)?;
        let mut byte = [0u8; 1];
        (basic.clients.transmit(client, &mut byte) == 1).then_some(byte[0])
    }

    fn usb_mut(&mut self, link: HostLink) -> Option<&mut UsbLink> {
        match link {
            HostLink::Basic => self.basic.as_mut().map(|b| &mut b.usb),
            HostLink::AtomUsb => Some(&mut self.atom_usb),
            HostLink::Network(_) => None,
        }
    }

    /// The Basic and the network client `link` is, if it is one.
    fn net_mut(&mut self, link: HostLink) -> Option<(&mut BasicBoard, NetClient)> {
        match link {
            HostLink::Network(client) => Some((self.basic.as_mut()?, client)),
            HostLink::Basic | HostLink::AtomUsb => None,
        }
    }

    /// A network client connects to the Basic (like a TCP client to its Wi-Fi server): the
    /// Basic opens a host link for it, with its own framer, queue and turn on the bus. `None`
    /// if the Basic refuses it (it serves `firmware_basic::MAX_HOST_LINKS` links, the USB one
    /// included) or the robot has no Basic.
    pub fn connect(&mut self) -> Option<HostLink> {
        let basic = self.basic.as_mut()?;
        let client = basic.clients.connect(basic.firmware.basic_mut())?;
        Some(HostLink::Network(client))
    }

    /// A network client leaves: the Basic closes its link. No-op for the USB links.
    pub fn disconnect(&mut self, link: HostLink) {
        let (HostLink::Network(client), Some(basic)) = (link, self.basic.as_mut()) else {
            return;
        };
        basic.clients.disconnect(basic.firmware.basic_mut(), client);
    }

    /// True while `link` reaches a board: always for the USB ports of the boards there are,
    /// for a network client until it disconnects or the Basic restarts.
    pub fn link_connected(&self, link: HostLink) -> bool {
        match link {
            HostLink::Basic => self.basic.is_some(),
            HostLink::AtomUsb => true,
            HostLink::Network(client) => self
                .basic
                .as_ref()
                .is_some_and(|b| b.clients.is_connected(client)),
        }
    }

    /// Resets the Atom now (brown-out, reset button): its firmware starts again from
    /// [`Atom::new`] with its clock at 0 and its UART buffers empty. The servos keep their
    /// torque, goals and positions.
    pub fn reset_atom(&mut self) {
        self.atom = Atom::new(self.atom_config);
        self.atom_boot_ns = self.now_ns;
        self.bus.reset_station(self.atom_station);
    }

    /// Resets the Basic now, like [`VirtualRobot::reset_atom`]; what the host sent and the
    /// Basic had not read yet is lost, and so are its network clients' connections. No-op
    /// without a Basic.
    pub fn reset_basic(&mut self) {
        if let Some(basic) = self.basic.as_mut() {
            basic.firmware = BasicFirmware::new(basic.config, basic.program);
            basic.boot_ns = self.now_ns;
            basic.usb = UsbLink::new();
            basic.clients.clear();
            self.bus.reset_station(basic.station);
        }
    }

    /// Puts `bytes` on the bus from a noise source starting now, one per byte time, colliding
    /// with whatever else is on the wire.
    pub fn inject_bus_noise(&mut self, bytes: &[u8]) {
        use protocol_core::BytePort;
        if let Some(mut port) = self.bus.port(self.noise_station) {
            port.write(bytes);
        }
        self.bus.start_transmissions(self.now_ns);
    }

    /// Runs the robot until virtual time `t_us` (no-op if that is not in the future).
    pub fn run_until(&mut self, t_us: u64) {
        self.run_until_ns(t_us.saturating_mul(1_000));
    }

    /// Runs the robot until virtual time `target` in nanoseconds (no-op if that is not in the
    /// future).
    pub fn run_until_ns(&mut self, target: u64) {
        while self.now_ns < target {
            let next = self.next_event_ns(target).max(self.now_ns + 1);
            self.step(next);
        }
    }

    /// The next instant something happens (a poll is due, a byte ends, a servo answers), at
    /// most `limit_ns`.
    fn next_event_ns(&self, limit_ns: u64) -> u64 {
        let mut next = self.next_poll_ns.min(limit_ns);
        let mut consider = |t: Option<u64>| {
            if let Some(t) = t {
                next = next.min(t);
            }
        };
        consider(self.bus.next_event_ns());
        consider(self.atom_usb.next_event_ns());
        consider(self.basic.as_ref().and_then(|b| b.usb.next_event_ns()));
        consider(self.atom_loop.next_event_ns());
        consider(
            self.basic
                .as_ref()
                .and_then(|b| b.main_loop.next_event_ns()),
        );
        consider(self.servos.next_event_ns());
        next
    }

    /// Runs the robot for `dt_us` more microseconds of virtual time.
    pub fn run_for(&mut self, dt_us: u64) {
        self.run_until(self.now_us() + dt_us);
    }

    /// One instant: bytes that ended arrive, servos react, boards are polled, and every free
    /// transmitter starts its next byte.
    fn step(&mut self, now_ns: u64) {
        self.now_ns = now_ns;
        self.bus.deliver(now_ns);
        self.atom_usb.deliver(now_ns);
        if let Some(basic) = self.basic.as_mut() {
            basic.usb.deliver(now_ns);
        }
        self.bus.take_heard(&mut self.heard);
        for heard in self.heard.drain(..) {
            self.servos.hear(&heard);
        }
        self.servos.transmit_due(now_ns, &mut self.bus);
        if let Some(basic) = self.basic.as_mut()
            && basic.main_loop.runs_at(now_ns)
            && let Some(mut bus) = self.bus.port(basic.station)
        {
            let mut usb = basic.usb.board_port(now_ns);
            let mut io = SimBoardIo {
                io: &mut basic.io,
                flash: &mut basic.flash,
            };
            let basic_us = (now_ns - basic.boot_ns) / 1_000;
            let before = io.flash.flash().map(FlashWork::of);
            basic
                .firmware
                .poll(&mut basic.clients, basic_us, &mut usb, &mut bus, &mut io);
            let after = io.flash.flash().map(FlashWork::of);
            let until = now_ns + flash_busy_us(before, after, self.flash_timing) * 1_000;
            let board = (&mut basic.main_loop, basic.station, &mut basic.usb);
            stand_still_until(board, &mut self.bus, now_ns, until);
            self.mark_basic(now_ns);
        }
        if self.atom_loop.runs_at(now_ns)
            && let Some(mut bus) = self.bus.port(self.atom_station)
        {
            let mut usb = self.atom_usb.board_port(now_ns);
            let atom_us = (now_ns - self.atom_boot_ns) / 1_000;
            let before = self.atom_io.params.flash().map(FlashWork::of);
            self.atom
                .poll(atom_us, &mut bus, &mut usb, &mut self.atom_io);
            let after = self.atom_io.params.flash().map(FlashWork::of);
            let until = now_ns + flash_busy_us(before, after, self.flash_timing) * 1_000;
            let board = (&mut self.atom_loop, self.atom_station, &mut self.atom_usb);
            stand_still_until(board, &mut self.bus, now_ns, until);
            self.note_collision(now_ns);
        }
        self.bus.start_transmissions(now_ns);
        self.next_poll_ns = now_ns + POLL_PERIOD_NS;
    }

    /// Logs the Atom's collision the first time it is seen.
    fn note_collision(&mut self, now_ns: u64) {
        let Some(collision) = self.atom.collision() else {
            return;
        };
        if self.collisions.last().map(|(_, c)| c) != Some(&collision) {
            self.collisions.push((now_ns, collision));
        }
    }

    /// Every collision the Atom detected so far: when (virtual time, ns) and what
    /// ([`firmware_atom::collision::Collision`]), oldest first.
    pub fn collisions(&self) -> &[(u64, Collision)] {
        &self.collisions
    }

    /// Sends `request` to the Basic's USB port and runs until the first complete frame comes
    /// back or pymycobot's reply deadline (0.5 s) passes. Other bytes before it are skipped.
    pub fn transact(&mut self, request: &Frame) -> Option<Frame> {
        self.transact_on(HostLink::Basic, request)
    }

    /// Like [`VirtualRobot::transact`] on any host link.
    pub fn transact_on(&mut self, link: HostLink, request: &Frame) -> Option<Frame> {
        self.link_write(link, &request.to_bytes());
        self.await_frame(link, HOST_REPLY_DEADLINE_US)
    }

    /// Runs until a complete host frame has arrived on `link` or `timeout_us` has passed, and
    /// returns it. Bytes before the frame are skipped; bytes after it stay unread (for
    /// [`VirtualRobot::link_read`] or the next call), so a duplicate reply cannot hide.
    pub fn await_frame(&mut self, link: HostLink, timeout_us: u64) -> Option<Frame> {
        let deadline = self.now_us().saturating_add(timeout_us);
        let mut decoder = FrameDecoder::new();
        loop {
            while let Some(byte) = self.link_receive(link) {
                if let Some(frame) = decoder.push(byte) {
                    return Some(frame);
                }
            }
            if self.now_us() >= deadline {
                return None;
            }
            // A byte at 115200 takes 87 us: look at what came back once per byte time.
            self.run_until(deadline.min(self.now_us() + 87));
        }
    }

    /// Sends `request` on the Basic's USB port like pymycobot does (one try) and returns the
    /// typed reply.
    pub fn ask(&mut self, request: &Request) -> Result<Reply, AskError> {
        self.ask_on(HostLink::Basic, request)
    }

    /// Like [`VirtualRobot::ask`] on any host link.
    pub fn ask_on(&mut self, link: HostLink, request: &Request) -> Result<Reply, AskError> {
        let frame = request.to_frame();
        let reply = self.transact_on(link, &frame).ok_or(AskError::NoReply)?;
        if reply.cmd() != frame.cmd() {
            return Err(AskError::WrongCommand { cmd: reply.cmd() });
        }
        Reply::parse(request.reply_kind(), &reply).map_err(AskError::BadReply)
    }

    /// Runs until `done(self)` holds (checked every millisecond of virtual time) or `timeout_us`
    /// passes; returns whether it held.
    pub fn run_until_true(&mut self, timeout_us: u64, mut done: impl FnMut(&Self) -> bool) -> bool {
        let deadline = self.now_us() + timeout_us;
        while !done(self) {
            if self.now_us() >= deadline {
                return false;
            }
            self.run_for(1_000);
        }
        true
    }

    /// The joint angles the servos' shafts are really at (present positions converted with the
    /// Atom's joint signs): what a protractor on the arm would read.
    pub fn measured_angles(&self) -> [Centideg; 6] {
        let config = self.atom.config();
        std::array::from_fn(|j| {
            let position = config
                .servo_ids
                .get(j)
                .and_then(|&id| self.servo(id))
                .map_or(2048, |s| s.present_position());
            config.steps_to_angle(j, Steps(position as i16))
        })
    }

    /// Joint angles in degrees from the shafts' true positions (finer than the servos' step;
    /// [`super::measure`] turns them into the true pose of the flange).
    pub fn shaft_angles_deg(&self) -> [f64; 6] {
        let config = self.atom.config();
        std::array::from_fn(|j| {
            let steps = config
                .servo_ids
                .get(j)
                .and_then(|&id| self.servo(id))
                .map_or(2048.0, |s| s.shaft_steps());
            let degrees = (steps - 2048.0) * 360.0 / 4096.0;
            match config.joint_signs.get(j) {
                Some(firmware_atom::JointSign::Negative) => -degrees,
                _ => degrees,
            }
        })
    }

    /// The simulated servo with bus id `id` (its present register 5).
    pub fn servo(&self, id: u8) -> Option<&SimServo> {
        self.servos.get(id)
    }

    /// The simulated servo with bus id `id`, to inject faults or move it by hand.
    pub fn servo_mut(&mut self, id: u8) -> Option<&mut SimServo> {
        self.servos.get_mut(id)
    }

    /// A hand turns the released servo `id` from where it is now to present position
    /// `position` (steps) over `duration_us`, speeding up and slowing down smoothly
    /// ([`SimServo::move_by_hand_over`]); `false` if there is no such servo.
    pub fn turn_by_hand(&mut self, id: u8, position: u16, duration_us: u64) -> bool {
        let now = self.now_ns;
        match self.servos.get_mut(id) {
            Some(servo) => {
                servo.move_by_hand_over(position, now, duration_us.saturating_mul(1_000));
                true
            }
            None => false,
        }
    }

    /// Puts `obstacle` in its joint's way ([`Obstacle`]); `false` if that joint has no servo.
    pub fn add_obstacle(&mut self, obstacle: Obstacle) -> bool {
        obstacle.place(&mut self.servos, self.atom.config())
    }

    /// Makes a servo's answers late or lost ([`ReplyFault`]); `false` if there is no such
    /// servo.
    pub fn add_reply_fault(&mut self, fault: ReplyFault) -> bool {
        fault.apply(&mut self.servos)
    }

    /// Pushes joint `joint` (1..=6) with an external torque of `permille` thousandths of its
    /// servo's maximum torque, towards higher angles for a positive value (0 lets go):
    /// someone leaning on the arm ([`contact::push`]). `false` if there is no such joint.
    pub fn push_joint(&mut self, joint: u8, permille: i16) -> bool {
        contact::push(&mut self.servos, self.atom.config(), joint, permille)
    }

    /// Sends `request` as one sample of a stream: writes it on the Basic's USB, runs for the
    /// stream's period `period_us` and drops the replies, as a client that streams without
    /// reading them (a ROS node streaming `send_angles`).
    pub fn stream_sample(&mut self, request: &Request, period_us: u64) {
        self.host_write(&request.to_frame().to_bytes());
        self.run_for(period_us);
        let mut replies = Vec::new();
        self.host_read(&mut replies);
    }

    /// Every simulated servo, in the order they were built (ids 1..7 at power-up).
    pub fn servos(&self) -> impl Iterator<Item = &SimServo> {
        self.servos.iter()
    }

    /// The bus station of the servo built for `id` (for reading a bus trace).
    pub fn servo_station(&self, id: u8) -> Option<StationId> {
        self.servos.station(id)
    }

    /// The Atom firmware, for inspection.
    pub fn atom(&self) -> &Atom {
        &self.atom
    }

    /// The Atom's bus station (for reading a bus trace).
    pub fn atom_station(&self) -> StationId {
        self.atom_station
    }

    /// The Atom's pins, LEDs and button.
    pub fn atom_io(&self) -> &RecordingIo {
        &self.atom_io
    }

    /// The Atom's pins, LEDs and button, to set inputs or press the button.
    pub fn atom_io_mut(&mut self) -> &mut RecordingIo {
        &mut self.atom_io
    }

    /// The Basic firmware, if the robot has one.
    pub fn basic(&self) -> Option<&Basic> {
        self.basic.as_ref().map(|b| b.firmware.basic())
    }

    /// What the Basic's teach-and-play program is doing, if it runs one
    /// ([`RobotConfig::basic_program`]).
    pub fn teach_status(&self) -> Option<TeachStatus> {
        match &self.basic.as_ref()?.firmware {
            BasicFirmware::Teach(programmed) => Some(programmed.program().status()),
            BasicFirmware::Transponder(_) => None,
        }
    }

    /// The Basic's bus station, if the robot has a Basic.
    pub fn basic_station(&self) -> Option<StationId> {
        self.basic.as_ref().map(|b| b.station)
    }

    /// The Basic's pins and sensors, if the robot has a Basic.
    pub fn basic_io_mut(&mut self) -> Option<&mut SimBasicIo> {
        self.basic.as_mut().map(|b| &mut b.io)
    }

    /// The shared bus, for inspection (collisions, overruns).
    pub fn bus(&self) -> &Bus {
        &self.bus
    }

    /// The shared bus, to switch tracing on and take the trace.
    pub fn bus_mut(&mut self) -> &mut Bus {
        &mut self.bus
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use protocol_core::command::{Reply, Request};
    use protocol_core::timing::wire_time_us;

    #[test]
    fn time_only_moves_forward_and_exactly_as_asked() {
        let mut robot = VirtualRobot::new(RobotConfig::default());
        robot.run_for(1_234);
        assert_eq!(robot.now_us(), 1_234);
        robot.run_until(1_000);
        assert_eq!(robot.now_us(), 1_234, "the past is a no-op");
        robot.run_until(5_000);
        assert_eq!(robot.now_us(), 5_000);
    }

    #[test]
    fn the_basic_answers_over_a_115200_link_no_faster_than_the_wire() {
        let mut robot = VirtualRobot::new(RobotConfig::default());
        robot.run_for(10_000);
        let request = Request::GetBasicVersion.to_frame();
        let start = robot.now_us();
        let reply = robot
            .transact(&request)
            .expect("the Basic answers its version");
        assert_eq!(reply.cmd(), request.cmd());
        assert!(matches!(
            Reply::parse(Request::GetBasicVersion.reply_kind(), &reply),
            Ok(Reply::Byte(_))
        ));
        let both_ways = wire_time_us(
            (request.encoded_len() + reply.encoded_len()) as u32,
            HOST_BAUD,
        );
        assert!(robot.now_us() - start >= both_ways);
    }

    #[test]
    fn await_frame_leaves_what_follows_the_frame_unread() {
        let mut robot = VirtualRobot::new(RobotConfig::default());
        robot.run_for(10_000);
        let request = Request::GetBasicVersion.to_frame();
        let mut twice = request.to_bytes().to_vec();
        twice.extend_from_slice(&request.to_bytes());
        robot.host_write(&twice);
        let first = robot.await_frame(HostLink::Basic, HOST_REPLY_DEADLINE_US);
        assert_eq!(first.map(|f| f.cmd()), Some(request.cmd()));
        robot.run_for(50_000);
        let mut rest = Vec::new();
        robot.host_read(&mut rest);
        let mut frames = Vec::new();
        FrameDecoder::new().feed(&rest, |f| frames.push(f));
        assert_eq!(frames.len(), 1, "the second reply is intact: {rest:02x?}");
    }

    #[test]
    fn the_next_byte_to_the_host_is_known_while_it_is_on_the_wire() {
        let mut robot = VirtualRobot::new(RobotConfig::default());
        robot.run_for(10_000);
        assert_eq!(robot.link_next_arrival_ns(HostLink::Basic), None);
        robot.host_write(&Request::GetBasicVersion.to_frame().to_bytes());
        let byte_ns = protocol_core::timing::wire_time_ns(1, HOST_BAUD);
        let mut arrivals = Vec::new();
        for _ in 0..2_000 {
            if let Some(t) = robot.link_next_arrival_ns(HostLink::Basic)
                && arrivals.last() != Some(&t)
            {
                arrivals.push(t);
            }
            robot.run_for(10);
        }
        // The Basic's answer, `FE FE 03 C1 0A FA`: six bytes, one byte time apart.
        assert_eq!(arrivals.len(), 6, "{arrivals:?}");
        assert!(arrivals.windows(2).all(|w| w[1] - w[0] == byte_ns));
        let net = robot.connect().expect("a network client");
        assert_eq!(robot.link_next_arrival_ns(net), None, "no wire time");
    }

    #[test]
    fn without_a_basic_the_basic_port_is_dead() {
        let mut robot = VirtualRobot::new(RobotConfig {
            with_basic: false,
            ..RobotConfig::default()
        });
        assert!(robot.basic().is_none());
        assert_eq!(robot.ask(&Request::GetBasicVersion), Err(AskError::NoReply));
    }

    #[test]
    fn the_same_inputs_give_the_same_bus_traffic() {
        let session = || {
            let mut robot = VirtualRobot::new(RobotConfig::default());
            robot.bus_mut().set_tracing(true);
            robot.run_for(30_000);
            robot.host_write(&Request::GetAngles.to_frame().to_bytes());
            robot.inject_bus_noise(&[0x12, 0x34]);
            robot.run_for(30_000);
            robot.bus_mut().take_trace()
        };
        let first = session();
        assert!(!first.is_empty());
        assert_eq!(first, session());
    }

    #[test]
    fn a_slow_main_loop_answers_later() {
        let round_trip = |atom_loop_us| {
            let mut robot = VirtualRobot::new(RobotConfig {
                with_basic: false,
                atom_loop_us,
                ..RobotConfig::default()
            });
            robot.run_for(100_000);
            let start = robot.now_us();
            let reply = robot.transact_on(HostLink::AtomUsb, &Request::IsPowerOn.to_frame());
            assert!(reply.is_some(), "loop {atom_loop_us} us: no answer");
            robot.now_us() - start
        };
        let fast = round_trip(0);
        let slow = round_trip(5_000);
        assert!(slow > fast + 1_000, "fast {fast} us, slow {slow} us");
    }

    #[test]
    fn measured_angles_follow_the_shafts() {
        let mut robot = VirtualRobot::new(RobotConfig::default());
        robot
            .servo_mut(3)
            .expect("servo 3")
            .move_by_hand(2048 + 1024);
        let angles = robot.measured_angles();
        assert_eq!(angles[2], Centideg(9_000));
        assert_eq!(angles[0], Centideg(0));
    }

    #[test]
    fn servos_are_found_by_their_present_id() {
        let robot = VirtualRobot::new(RobotConfig::default());
        assert_eq!(robot.servos().count(), 7);
        assert_eq!(robot.servo(7).map(SimServo::id), Some(7));
        assert!(robot.servo(8).is_none());
        assert!(robot.servo_station(1).is_some());
    }
}

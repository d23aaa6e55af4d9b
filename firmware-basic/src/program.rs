//! A program of your own on the Basic, as the manual's "Maker" path has it (its section 2: a
//! sketch on the Basic drives the Atom with MyCobotBasic's calls), here with the
//! [`mycobot_api`] crate. [`Programmed`] runs a [`Program`] beside the transponder in the same
//! loop:
//!
//! * the program speaks to the arm through an in-process host link of the Basic's router
//!   ([`ProgramLink`], a link of kind [`LinkKind::Program`]): its requests take their turn on the
//!   bus with every other client's and follow the forwarder's bus rules (the Basic's 60 us of
//!   silence, one request at a time, late replies dropped), so a program can never garble
//!   the bus the Atom polls its servos on;
//! * the USB link stays open, so a PC can watch (or stop) the arm while the program runs;
//! * the front buttons are the program's: the transponder's own uses of them (A powers on, C
//!   held changes the dialect) are off;
//! * the program never blocks the loop: it starts a call with [`Arm::start`] and polls it
//!   with [`Arm::poll`] on later passes (`mycobot_api::MyCobot::start` and `poll`). The
//!   blocking calls of the crate are not offered here: in the loop that must also forward
//!   their frames, a blocking call would wait for a reply that only the next pass can bring.
//!
//! [`crate::teach`] is the worked example: teach and play. A smaller one, a program that
//! sends the arm home when button A is pressed and remembers how that went:
//!
//! ```
//! use firmware_basic::{Arm, BasicConfig, Buttons, NullIo, Program, Programmed};
//! use mycobot_api::{Call, Error};
//! use protocol_core::NullPort;
//! use protocol_core::command::Request;
//! use protocol_core::units::{Centideg, SpeedPercent};
//!
//! #[derive(Default)]
//! struct HomeOnA {
//!     was_down: bool,
//!     call: Option<Call>,
//!     last: Option<Result<(), Error>>,
//! }
//!
//! impl Program for HomeOnA {
//!     fn poll(&mut self, _now_us: u64, buttons: Buttons, arm: &mut Arm) {
//!         if buttons.a && !self.was_down {
//!             let home = Request::SendAngles { angles: [Centideg(0); 6], speed: SpeedPercent::MAX };
//!             match arm.start(&home) {
//!                 Ok(call) => self.call = Some(call),
//!                 Err(e) => self.last = Some(Err(e)),
//!             }
//!         }
//!         self.was_down = buttons.a;
//!         if let Some(call) = self.call.as_mut()
//!             && let Some(outcome) = arm.poll(call)
//!         {
//!             self.last = Some(outcome.map(|_| ()));
//!             self.call = None;
//!         }
//!     }
//! }
//!
//! // On a board: the USB UART, the bus UART and the board's IO; here nothing is attached.
//! let mut basic = Programmed::new(BasicConfig::default(), HomeOnA::default());
//! for pass in 0..1_000_u64 {
//!     basic.poll(pass * 100, &mut NullPort, &mut NullPort, &mut NullIo);
//! }
//! assert!(basic.program().last.is_none(), "no button was pressed");
//! ```

use mycobot_api::{Call, Error, MyCobot};
use protocol_core::BytePort;
use protocol_core::command::{Reply, Request};
use protocol_core::dialect::Dialect;

use crate::basic::Basic;
use crate::config::BasicConfig;
use crate::dialect::DialectStore;
use crate::host_link::{HOST_TX_CAPACITY, HOST_WRITE_CHUNK, LinkKind};
use crate::io::{BasicIo, Buttons};
use crate::request::LinkId;
use crate::router::HostPorts;
use crate::wifi::WifiStore;

/// Bytes a program's requests may queue for the Basic: several requests, where a program has
/// one at a time.
pub const PROGRAM_TX_CAPACITY: usize = 256;

/// A program that runs on the Basic: polled on every pass of the loop with the time, the
/// front buttons and the arm.
pub trait Program {
    /// One step at `now_us` (monotonic microseconds): read `buttons`, start calls on `arm`
    /// or poll the one under way. Must return at once: the transponder runs between steps.
    fn poll(&mut self, now_us: u64, buttons: Buttons, arm: &mut Arm);
}

/// The in-process host link between a program and the Basic's router: what the program
/// writes is a client's request on [`LinkKind::Program`], what the router sends that link is
/// the program's to read. Bounded both ways; what does not fit is dropped (the call then
/// times out, as on a line that lost bytes).
#[derive(Debug, Default)]
pub struct ProgramLink {
    to_basic: heapless::Deque<u8, PROGRAM_TX_CAPACITY>,
    from_basic: heapless::Deque<u8, HOST_TX_CAPACITY>,
}

impl BytePort for ProgramLink {
    fn read_byte(&mut self) -> Option<u8> {
        self.from_basic.pop_front()
    }

    fn write(&mut self, bytes: &[u8]) {
        for &byte in bytes {
            if self.to_basic.push_back(byte).is_err() {
                break;
            }
        }
    }

    fn tx_idle(&self) -> bool {
        true
    }
}

/// The loop's time, handed to the program's calls on every pass.
#[derive(Clone, Copy, Debug, Default)]
pub struct LoopClock(u64);

impl mycobot_api::Clock for LoopClock {
    fn now_us(&mut self) -> u64 {
        self.0
    }
}

/// The arm, as a program on the Basic reaches it: [`mycobot_api::MyCobot`]'s non-blocking
/// half over the program's link.
#[derive(Debug)]
pub struct Arm {
    robot: MyCobot<ProgramLink, LoopClock>,
}

impl Arm {
    /// Writes `request` and returns at once (`MyCobot::start`); poll the call on later
    /// passes.
    pub fn start(&mut self, request: &Request) -> Result<Call, Error> {
        self.robot.start(request)
    }

    /// The call's outcome once it has one (`MyCobot::poll`): `None` while its reply may still
    /// come. Its reply comes on a later pass, once the transponder has forwarded the request.
    pub fn poll(&mut self, call: &mut Call) -> Option<Result<Option<Reply>, Error>> {
        self.robot.poll(call)
    }

    /// The dialect the program's calls speak: the Basic's setting, followed between calls.
    pub fn dialect(&self) -> Dialect {
        self.robot.dialect()
    }
}

/// The Basic running `P` beside its transponder: one per board, polled forever in place of
/// [`Basic`] alone.
#[derive(Debug)]
pub struct Programmed<P> {
    basic: Basic,
    /// The program's link; `None` only if the router had no room, which a new Basic has.
    link: Option<LinkId>,
    arm: Arm,
    program: P,
}

impl<P: Program> Programmed<P> {
    /// A Basic just powered up with `config`, running `program`.
    pub fn new(config: BasicConfig, program: P) -> Self {
        let mut basic = Basic::new(config);
        let link = basic.open_link(LinkKind::Program).ok();
        Self {
            basic,
            link,
            arm: Arm {
                robot: MyCobot::new(
                    ProgramLink::default(),
                    LoopClock::default(),
                    config.dialect.unwrap_or(Dialect::Pymycobot),
                ),
            },
            program,
        }
    }

    /// One pass at `now_us`: the program's step (with the buttons), then the transponder's
    /// ([`Basic::poll`], with the program's link among `hosts` and no buttons of its own).
    pub fn poll<H: HostPorts, B: BytePort, I: BasicIo>(
        &mut self,
        now_us: u64,
        hosts: &mut H,
        bus: &mut B,
        io: &mut I,
    ) {
        let buttons = io.buttons();
        *self.arm.robot.clock_mut() = LoopClock(now_us);
        self.program.poll(now_us, buttons, &mut self.arm);
        let mut ports = WithProgram {
            hosts,
            link: self.link,
            pipe: self.arm.robot.port_mut(),
        };
        self.basic
            .poll(now_us, &mut ports, bus, &mut WithoutButtons(io));
        self.arm.robot.set_dialect(self.basic.status().dialect);
    }

    /// The transponder (its status for the screen, its links).
    pub fn basic(&self) -> &Basic {
        &self.basic
    }

    /// The transponder, to open and close network links.
    pub fn basic_mut(&mut self) -> &mut Basic {
        &mut self.basic
    }

    /// The program (its status for the screen).
    pub fn program(&self) -> &P {
        &self.program
    }
}

/// The board's host links and the program's, as one [`HostPorts`].
struct WithProgram<'a, H> {
    hosts: &'a mut H,
    link: Option<LinkId>,
    pipe: &'a mut ProgramLink,
}

impl<H: HostPorts> HostPorts for WithProgram<'_, H> {
    fn read_from(&mut self, link: LinkId) -> Option<u8> {
        if Some(link) == self.link {
            self.pipe.to_basic.pop_front()
        } else {
            self.hosts.read_from(link)
        }
    }

    fn write_to(&mut self, link: LinkId, bytes: &[u8]) {
        if Some(link) == self.link {
            for &byte in bytes {
                if self.pipe.from_basic.push_back(byte).is_err() {
                    break;
                }
            }
        } else {
            self.hosts.write_to(link, bytes);
        }
    }

    fn tx_idle_on(&self, link: LinkId) -> bool {
        if Some(link) == self.link {
            self.pipe.from_basic.capacity() - self.pipe.from_basic.len() >= HOST_WRITE_CHUNK
        } else {
            self.hosts.tx_idle_on(link)
        }
    }
}

/// The board's IO with the buttons left to the program.
struct WithoutButtons<'a, I>(&'a mut I);

impl<I: BasicIo> BasicIo for WithoutButtons<'_, I> {
    fn set_output(&mut self, pin: u8, high: bool) -> bool {
        self.0.set_output(pin, high)
    }

    fn read_input(&mut self, pin: u8) -> Option<bool> {
        self.0.read_input(pin)
    }

    fn tof_distance_mm(&mut self) -> Option<u16> {
        self.0.tof_distance_mm()
    }

    fn buttons(&mut self) -> Buttons {
        Buttons::default()
    }

    fn wifi_store(&mut self) -> Option<&mut dyn WifiStore> {
        self.0.wifi_store()
    }

    fn dialect_store(&mut self) -> Option<&mut dyn DialectStore> {
        self.0.dialect_store()
    }
}

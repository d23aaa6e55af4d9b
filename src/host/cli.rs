//! The command line of the virtual robot.

use std::net::SocketAddr;
use std::path::PathBuf;

use clap::{Parser, ValueEnum};

use crate::sim::contact::Obstacle;
use crate::sim::reply_faults::ReplyFault;
use crate::sim::{BasicProgram, FlashTiming, HostLink};

/// Virtual myCobot 280 M5: the real Basic and Atom firmware logic, simulated servos, served in
/// real time on a pseudo-terminal (and optionally TCP) to pymycobot or any serial client, with
/// a live 3D view in the browser.
#[derive(Debug, Parser)]
#[command(version, about)]
pub struct Cli {
    /// Also create a symlink at PATH to the pseudo-terminal, e.g. `--pty-link /tmp/mycobot`
    /// then `MyCobot280("/tmp/mycobot")`. While the robot runs it holds PATH.lock (with its
    /// pid) locked, so a second robot on the same PATH refuses to start; the kernel drops the
    /// lock when the robot ends, however it ends, and a link left by a robot that is gone is
    /// replaced. On exit the link is removed if it still points to this robot's terminal.
    #[arg(long, value_name = "PATH")]
    pub pty_link: Option<PathBuf>,

    /// Also serve the host protocol over TCP (raw frames, like the Basic's Wi-Fi server), e.g.
    /// `--tcp` then `MyCobot280Socket("127.0.0.1", 9000)`. Alone, on 127.0.0.1 at the port in
    /// the Basic's Wi-Fi settings (9000 until `set_server_port` changes it; the server then
    /// moves there, as the board does). With ADDR:PORT, there and nowhere else (port 0 picks a
    /// free port). The address used is printed.
    #[arg(long, value_name = "ADDR:PORT", num_args = 0..=1)]
    #[allow(clippy::option_option, reason = "absent, alone, or with an address")]
    pub tcp: Option<Option<SocketAddr>>,

    /// The file the simulated Basic keeps its flash in (its Wi-Fi settings, which
    /// `set_ssid_pwd` and `set_server_port` change), so they survive a restart. Default:
    /// `$XDG_STATE_HOME/open-mycobot/basic-flash.bin` (`~/.local/state/...` without it).
    #[arg(long, value_name = "PATH")]
    pub basic_flash: Option<PathBuf>,

    /// The protocol dialect the Basic's clients speak from the start (docs/protocol.md,
    /// "Dialects"): pymycobot's, or the vendor manual's (`seed`: set commands unanswered,
    /// joints numbered from 0, 0x28 stops). Kept in the Basic's flash like the board's button
    /// C setting; without it, the stored dialect (pymycobot's at first).
    #[arg(long, value_enum)]
    pub dialect: Option<DialectArg>,

    /// Which board's USB serial the clients talk to: the Basic (as with the real arm's USB
    /// cable) or the Atom's own USB port (a direct link to the arm's controller).
    #[arg(long, value_enum, default_value_t = Port::Basic)]
    pub port: Port,

    /// Serve the live 3D view on ADDR:PORT (default 127.0.0.1:8280; if that is taken, a free
    /// port is used and printed). A chosen address must be free; port 0 picks one.
    #[arg(long, value_name = "ADDR:PORT", conflicts_with = "no_web")]
    pub web: Option<SocketAddr>,

    /// Do not serve the 3D view.
    #[arg(long)]
    pub no_web: bool,
    /// A rigid obstacle in joint J's way at DEG degrees (repeatable): the joint cannot move past
    /// it from the side it starts on, e.g. `--obstacle 2:-30`. The firmware feels it only
    /// through what the joint's servo reports, as on the real arm.
    #[arg(long = "obstacle", value_name = "J:DEG", allow_hyphen_values = true)]
    pub obstacles: Vec<Obstacle>,
    /// Every answer of servo ID (1..7, 7 the gripper) starts US microseconds late (repeatable),
    /// e.g. `--late-replies 3:300`: past the Atom's deadline from about 200 us on, and still on
    /// the wire when it comes, as with a slow servo or a slow board.
    #[arg(long = "late-replies", value_name = "ID:US", value_parser = ReplyFault::late)]
    pub late_replies: Vec<ReplyFault>,
    /// Servo ID loses PER_MILLE of every thousand answers, spread evenly (repeatable), e.g.
    /// `--lost-replies 2:100` (every tenth), `--lost-replies 2:1000` (all).
    #[arg(long = "lost-replies", value_name = "ID:PER_MILLE", value_parser = ReplyFault::lost)]
    pub lost_replies: Vec<ReplyFault>,

    /// A program the Basic runs beside its transponder, as a board flashed with its image
    /// does: `teach`, teach and play (the image basic-teach): A records the arm moved by hand,
    /// B plays the record back, C stops. Its buttons are pressed by the keys a, b and c on the
    /// robot's standard input (each followed by Enter on a terminal) and by the buttons of the
    /// 3D view, which shows what the program does. Without a program the keys are not read and
    /// the view has no buttons. Not with `--emulated-*`: the emulated Basic runs its own image.
    #[arg(long, value_enum, value_name = "PROGRAM")]
    pub basic_program: Option<BasicProgramArg>,

    /// How long a board stands still while its flash erases or writes (loop stopped, UART
    /// receiving into its 128-byte FIFO only): the datasheet's typical times, its worst case,
    /// or no time at all.
    #[arg(long, value_enum, default_value_t = FlashTiming::Typical)]
    pub flash_timing: FlashTiming,

    /// The Atom is an emulated chip running the real image (tools/emulate, docs/boards.md
    /// "Emulated boards"): its bus UART (UART1) is the socket at ADDR:PORT (QEMU
    /// `-serial tcp:ADDR:PORT,server=on`), on the simulated wire in place of the host-built Atom.
    #[arg(long, value_name = "ADDR:PORT", requires = "emulated_host")]
    pub emulated_atom: Option<SocketAddr>,
    /// Like `--emulated-atom`, for the Basic: its bus UART is the socket at ADDR:PORT.
    #[arg(long, value_name = "ADDR:PORT", requires_all = ["emulated_atom", "emulated_host"])]
    pub emulated_basic: Option<SocketAddr>,
    /// The emulated front board's host UART (UART0: the Basic's, or the Atom's when it is
    /// alone) at ADDR:PORT: the pseudo-terminal's clients talk to it.
    #[arg(long, value_name = "ADDR:PORT", requires = "emulated_atom", conflicts_with_all = ["tcp", "port"])]
    pub emulated_host: Option<SocketAddr>,
}

/// Where the simulated Basic's flash is kept without `--basic-flash`: `open-mycobot/
/// basic-flash.bin` in `$XDG_STATE_HOME`, or in `$HOME/.local/state`; `None` if neither is set.
pub fn default_basic_flash() -> Option<PathBuf> {
    let state = std::env::var_os("XDG_STATE_HOME")
        .filter(|dir| !dir.is_empty())
        .map(PathBuf::from)
        .or_else(|| {
            std::env::var_os("HOME")
                .filter(|dir| !dir.is_empty())
                .map(|home| PathBuf::from(home).join(".local/state"))
        })?;
    Some(state.join("open-mycobot/basic-flash.bin"))
}

/// A protocol dialect, as the command line names it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum DialectArg {
    /// pymycobot's protocol (every command answered).
    Pymycobot,
    /// The vendor manual's protocol.
    Seed,
}

impl From<DialectArg> for protocol_core::dialect::Dialect {
    fn from(arg: DialectArg) -> Self {
        match arg {
            DialectArg::Pymycobot => Self::Pymycobot,
            DialectArg::Seed => Self::Seed,
        }
    }
}

/// A program of the Basic's, as the command line names it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum BasicProgramArg {
    /// Teach and play: A records a hand move, B plays it back, C stops.
    Teach,
}

impl BasicProgramArg {
    /// The program's name on the command line and in the start-up lines.
    pub fn name(self) -> &'static str {
        match self {
            Self::Teach => "teach",
        }
    }
}

impl From<BasicProgramArg> for BasicProgram {
    fn from(arg: BasicProgramArg) -> Self {
        match arg {
            BasicProgramArg::Teach => Self::Teach,
        }
    }
}

/// A USB serial port of the virtual arm.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Port {
    /// The Basic's USB serial in the base.
    Basic,
    /// The Atom's USB serial at the end of the arm.
    AtomUsb,
}

impl Port {
    /// What the pseudo-terminal stands for, as the start-up line names it.
    pub fn serial_name(self) -> &'static str {
        match self {
            Port::Basic => "the Basic's USB serial",
            Port::AtomUsb => "the Atom's USB serial",
        }
    }
}

impl From<Port> for HostLink {
    fn from(port: Port) -> Self {
        match port {
            Port::Basic => HostLink::Basic,
            Port::AtomUsb => HostLink::AtomUsb,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn options_parse_and_bad_addresses_are_refused() {
        let cli = Cli::try_parse_from([
            "open-mycobot",
            "--pty-link",
            "/tmp/mycobot",
            "--tcp",
            "127.0.0.1:9000",
        ])
        .unwrap();
        assert_eq!(cli.pty_link, Some(PathBuf::from("/tmp/mycobot")));
        assert_eq!(cli.tcp, Some(Some("127.0.0.1:9000".parse().unwrap())));
        let alone = Cli::try_parse_from(["open-mycobot", "--tcp", "--no-web"]).unwrap();
        assert_eq!(alone.tcp, Some(None));
        assert!(alone.no_web);
        let flash = Cli::try_parse_from(["open-mycobot", "--basic-flash", "/tmp/f.bin"]).unwrap();
        assert_eq!(flash.basic_flash, Some(PathBuf::from("/tmp/f.bin")));

        let bare = Cli::try_parse_from(["open-mycobot"]).unwrap();
        assert!(bare.pty_link.is_none() && bare.tcp.is_none() && bare.basic_flash.is_none());
        assert_eq!(HostLink::from(bare.port), HostLink::Basic);
        let atom = Cli::try_parse_from(["open-mycobot", "--port", "atom-usb"]).unwrap();
        assert_eq!(HostLink::from(atom.port), HostLink::AtomUsb);

        assert!(Cli::try_parse_from(["open-mycobot", "--tcp", "9000"]).is_err());

        let blocked = ["open-mycobot", "--obstacle", "2:-30", "--obstacle", "1:45"];
        let blocked = Cli::try_parse_from(blocked).unwrap();
        assert_eq!(blocked.obstacles.len(), 2);
        assert_eq!(blocked.obstacles[0].angle.0, -3000);
        assert!(Cli::try_parse_from(["open-mycobot", "--obstacle", "9:10"]).is_err());

        let faulty = [
            "open-mycobot",
            "--late-replies",
            "3:300",
            "--lost-replies",
            "2:100",
            "--lost-replies",
            "5:1000",
        ];
        let faulty = Cli::try_parse_from(faulty).unwrap();
        assert_eq!(
            faulty.late_replies[0].trouble,
            crate::sim::reply_faults::ReplyTrouble::Late(300)
        );
        assert_eq!(faulty.lost_replies.len(), 2);
        assert!(Cli::try_parse_from(["open-mycobot", "--lost-replies", "2:2000"]).is_err());
    }

    #[test]
    fn emulated_boards_need_a_host_uart_and_the_atom() {
        let both = Cli::try_parse_from([
            "open-mycobot",
            "--emulated-atom",
            "127.0.0.1:5001",
            "--emulated-basic",
            "127.0.0.1:5011",
            "--emulated-host",
            "127.0.0.1:5010",
        ])
        .unwrap();
        assert_eq!(both.emulated_basic, Some("127.0.0.1:5011".parse().unwrap()));
        let atom_alone = ["open-mycobot", "--emulated-atom", "127.0.0.1:5001"];
        assert!(Cli::try_parse_from(atom_alone).is_err(), "no host UART");
        let basic_alone = [
            "--emulated-basic",
            "127.0.0.1:5011",
            "--emulated-host",
            "127.0.0.1:5010",
        ];
        assert!(Cli::try_parse_from(std::iter::once("open-mycobot").chain(basic_alone)).is_err());
        let with_tcp = [
            "--emulated-atom",
            "127.0.0.1:1",
            "--emulated-host",
            "127.0.0.1:2",
            "--tcp",
        ];
        assert!(Cli::try_parse_from(std::iter::once("open-mycobot").chain(with_tcp)).is_err());
    }

    #[test]
    fn the_view_is_on_by_default_and_can_be_moved_or_turned_off() {
        let bare = Cli::try_parse_from(["open-mycobot"]).unwrap();
        assert!(bare.web.is_none() && !bare.no_web);
        let moved = Cli::try_parse_from(["open-mycobot", "--web", "127.0.0.1:0"]).unwrap();
        assert_eq!(moved.web, Some("127.0.0.1:0".parse().unwrap()));
        assert!(
            Cli::try_parse_from(["open-mycobot", "--no-web"])
                .unwrap()
                .no_web
        );
        assert!(Cli::try_parse_from(["open-mycobot", "--web", "8280"]).is_err());
        assert!(
            Cli::try_parse_from(["open-mycobot", "--no-web", "--web", "127.0.0.1:0"]).is_err(),
            "both is a contradiction"
        );
    }

    #[test]
    fn the_basic_program_is_named_on_the_command_line() {
        let bare = Cli::try_parse_from(["open-mycobot"]).unwrap();
        assert_eq!(bare.basic_program, None);
        let teach = Cli::try_parse_from(["open-mycobot", "--basic-program", "teach"]).unwrap();
        assert_eq!(teach.basic_program, Some(BasicProgramArg::Teach));
        assert_eq!(
            teach.basic_program.map(BasicProgram::from),
            Some(BasicProgram::Teach)
        );
        assert_eq!(BasicProgramArg::Teach.name(), "teach");
        assert!(Cli::try_parse_from(["open-mycobot", "--basic-program", "dance"]).is_err());
    }

    #[test]
    fn clap_configuration_is_consistent() {
        use clap::CommandFactory;
        Cli::command().debug_assert();
    }
}

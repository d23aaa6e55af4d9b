//! `cargo run --release`: starts the virtual myCobot 280 in real time on a pseudo-terminal
//! (and optionally TCP), powered on with all joints at 0, until Ctrl-C or SIGTERM.

use std::io::Write;
use std::process::ExitCode;

use clap::Parser;
use open_mycobot::host::cli::Cli;
use open_mycobot::host::pty::PseudoTerminal;
use open_mycobot::host::pty_link::PtyLink;
use open_mycobot::host::realtime::{RealtimeDriver, ServedRobot, stop_on_signals};
use open_mycobot::host::tcp::TcpServer;
use open_mycobot::sim::{RobotConfig, VirtualRobot};

fn main() -> ExitCode {
    let cli = Cli::parse();
    match serve(&cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("open-mycobot: {e}");
            ExitCode::FAILURE
        }
    }
}

fn serve(cli: &Cli) -> Result<(), Box<dyn std::error::Error>> {
    // Signals first: a Ctrl-C during start-up must still remove the symlink.
    let stop = stop_on_signals()?;
    let pty =
        PseudoTerminal::open().map_err(|e| format!("cannot create a pseudo-terminal: {e}"))?;
    let tcp = cli
        .tcp
        .map(|addr| TcpServer::bind(addr).map_err(|e| format!("cannot listen on {addr}: {e}")))
        .transpose()?;
    let link = cli
        .pty_link
        .as_deref()
        .map(|path| {
            PtyLink::create(path, pty.slave_path())
                .map_err(|e| format!("cannot create the link {}: {e}", path.display()))
        })
        .transpose()?;

    let mut out = std::io::stdout().lock();
    writeln!(out, "virtual myCobot 280 on {}", pty.slave_path().display())?;
    if let Some(link) = &link {
        writeln!(out, "pty link {}", link.path().display())?;
    }
    if let Some(tcp) = &tcp {
        writeln!(out, "tcp on {}", tcp.local_addr()?)?;
    }
    writeln!(out, "ready (Ctrl-C to stop)")?;
    out.flush()?;
    drop(out);

    let robot = ServedRobot {
        robot: VirtualRobot::new(RobotConfig::default()),
        link: cli.port.into(),
    };
    RealtimeDriver::new(robot, pty, tcp).run(&stop)?;
    drop(link);
    let _ = writeln!(std::io::stdout(), "stopped");
    Ok(())
}

//! `cargo run --release`: starts the virtual myCobot 280 in real time on a pseudo-terminal
//! (and optionally TCP), powered on with all joints at 0, with its 3D view in the browser,
//! until Ctrl-C or SIGTERM.

use std::io::Write;
use std::process::ExitCode;
use std::sync::Arc;

use clap::Parser;
use open_mycobot::host::cli::Cli;
use open_mycobot::host::pty::PseudoTerminal;
use open_mycobot::host::pty_link::PtyLink;
use open_mycobot::host::realtime::{RealtimeDriver, ServedRobot, stop_on_signals};
use open_mycobot::host::tcp::TcpServer;
use open_mycobot::sim::{RobotConfig, VirtualRobot};
use open_mycobot::web::{self, Snapshot, StateBoard, WebServer};

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

    let board = Arc::new(StateBoard::new());
    let view = if cli.no_web {
        None
    } else {
        let listening = web::listen(cli.web).map_err(|e| {
            let addr = cli.web.unwrap_or(web::DEFAULT_ADDR);
            format!("cannot serve the view on {addr}: {e}")
        })?;
        let model = web::snapshot::model_json(&kinematics_core::ArmGeometry::MYCOBOT_280);
        let server = WebServer::start(listening.listener, Arc::clone(&board), model)
            .map_err(|e| format!("cannot start the view's server: {e}"))?;
        Some((server, listening.default_taken))
    };

    let mut out = std::io::stdout().lock();
    writeln!(
        out,
        "virtual myCobot 280: {} on {}",
        cli.port.serial_name(),
        pty.slave_path().display()
    )?;
    if let Some(link) = &link {
        writeln!(out, "pty link {}", link.path().display())?;
    }
    if let Some(tcp) = &tcp {
        writeln!(out, "tcp on {}", tcp.local_addr()?)?;
    }
    match &view {
        Some((server, None)) => writeln!(out, "view on {}", server.url())?,
        Some((server, Some(taken))) => {
            writeln!(out, "view on {} ({taken} is in use)", server.url())?;
        }
        None => {}
    }
    writeln!(out, "ready (Ctrl-C to stop)")?;
    out.flush()?;
    drop(out);

    let robot = ServedRobot {
        robot: VirtualRobot::new(RobotConfig::default()),
        link: cli.port.into(),
    };
    let mut driver = RealtimeDriver::new(robot, pty, tcp);
    if view.is_some() {
        driver = driver.observe_every(web::PUBLISH_PERIOD, move |served: &ServedRobot| {
            board.publish(Snapshot::of(&served.robot));
        });
    }
    driver.run(&stop)?;
    drop(view);
    drop(link);
    let _ = writeln!(std::io::stdout(), "stopped");
    Ok(())
}

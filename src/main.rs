//! `cargo run --release`: starts the virtual myCobot 280 in real time on a pseudo-terminal
//! (and optionally TCP), powered on with all joints at 0, with its 3D view in the browser,
//! until Ctrl-C or SIGTERM.

use std::io::Write;
use std::net::Ipv4Addr;
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use clap::Parser;
use firmware_atom::collision::Collision;
use firmware_basic::DialectStore;
use firmware_basic::wifi::WifiConfig;
use open_mycobot::host::buttons::{PressQueue, Presser, spawn_key_reader};
use open_mycobot::host::cli::{Cli, DialectArg, Port, default_basic_flash};
use open_mycobot::host::emulated::{CONNECT_TIMEOUT, Chardev, EmulatedBoards};
use open_mycobot::host::pty::PseudoTerminal;
use open_mycobot::host::pty_link::PtyLink;
use open_mycobot::host::realtime::{RealtimeDriver, ServedRobot, stop_on_signals};
use open_mycobot::host::tcp::TcpServer;
use open_mycobot::sim::external::EmulatedArm;
use open_mycobot::sim::{BasicFlashStore, RobotConfig, VirtualRobot};
use open_mycobot::web::{self, Snapshot, StateBoard, WebServer};
use protocol_core::dialect::Dialect;

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
    // The link before anything else is taken (the TCP port, the view's): a second robot on a
    // link that a running one serves says so, not that the port is in use.
    let link = cli
        .pty_link
        .as_deref()
        .map(|path| PtyLink::create(path, pty.slave_path()))
        .transpose()?;
    if cli.dialect == Some(DialectArg::Seed) && cli.port == Port::AtomUsb {
        return Err(
            "--dialect seed: the manual's protocol is the Basic's to speak (it \
                    translates for the Atom); the Atom's own port speaks pymycobot's"
                .into(),
        );
    }
    if let Some(program) = cli.basic_program
        && cli.emulated_atom.is_some()
    {
        return Err(format!(
            "--basic-program {}: with --emulated-* the boards run their real images, and a \
             Basic running {0} would be the image basic-teach, which tools/emulate does not \
             run yet",
            program.name()
        )
        .into());
    }
    if let Some(atom) = cli.emulated_atom {
        return serve_emulated(cli, atom, &stop, pty, link);
    }
    let flash_file = cli.basic_flash.clone().or_else(default_basic_flash);
    let mut flash = match &flash_file {
        Some(path) => BasicFlashStore::open(path)
            .map_err(|e| format!("cannot read the Basic's flash {}: {e}", path.display()))?,
        None => BasicFlashStore::in_memory(),
    };
    // `--tcp` alone: where the Basic's stored settings say, and wherever they move.
    let stored_port = WifiConfig::load(&mut flash).settings().port();
    let follow = cli.tcp.is_some_and(|addr| addr.is_none());
    let tcp = cli
        .tcp
        .map(|addr| {
            let addr = addr.unwrap_or_else(|| (Ipv4Addr::LOCALHOST, stored_port).into());
            TcpServer::bind(addr).map_err(|e| format!("cannot listen on {addr}: {e}"))
        })
        .transpose()?;

    // The Basic's buttons, pressed by the keys a, b, c and the view's buttons, when a program
    // of its own has them.
    let presses = cli.basic_program.map(|_| PressQueue::new());
    let board = Arc::new(StateBoard::new());
    let view = if cli.no_web {
        None
    } else {
        let listening = web::listen(cli.web).map_err(|e| {
            let addr = cli.web.unwrap_or(web::DEFAULT_ADDR);
            format!("cannot serve the view on {addr}: {e}")
        })?;
        let model = web::snapshot::model_json(&kinematics_core::ArmGeometry::MYCOBOT_280);
        let server = WebServer::start(
            listening.listener,
            Arc::clone(&board),
            model,
            presses.clone(),
        )
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
    match &flash_file {
        Some(path) => writeln!(out, "basic flash {}", path.display())?,
        None => writeln!(out, "basic flash in memory (no $XDG_STATE_HOME or $HOME)")?,
    }
    match cli.dialect {
        Some(arg) => writeln!(out, "protocol {} (--dialect)", Dialect::from(arg).name())?,
        None => {
            let stored = flash.load_dialect().ok().flatten().unwrap_or_default();
            writeln!(out, "protocol {} (the Basic's setting)", stored.name())?;
        }
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
    if let Some(program) = cli.basic_program {
        writeln!(
            out,
            "basic program {} (keys a, b, c or the view's buttons: A records a hand move, B \
             plays it, C stops)",
            program.name()
        )?;
    }
    let mut config = RobotConfig {
        flash_timing: cli.flash_timing,
        basic_program: cli.basic_program.map(Into::into),
        ..RobotConfig::default()
    };
    config.basic.dialect = cli.dialect.map(Dialect::from);
    let mut robot = VirtualRobot::new(config).with_basic_flash(flash);
    for &obstacle in &cli.obstacles {
        robot.add_obstacle(obstacle);
        writeln!(out, "obstacle: {obstacle}")?;
    }
    for &fault in cli.late_replies.iter().chain(&cli.lost_replies) {
        robot.add_reply_fault(fault);
        writeln!(out, "fault: {fault}")?;
    }
    writeln!(out, "ready (Ctrl-C to stop)")?;
    out.flush()?;
    drop(out);

    let robot = ServedRobot {
        robot,
        link: cli.port.into(),
    };
    let mut driver = RealtimeDriver::new(robot, pty, tcp);
    if follow {
        driver = driver.follow_server_port(Ipv4Addr::LOCALHOST.into(), |moved| match moved {
            Ok(addr) => println!("tcp on {addr} (set_server_port)"),
            Err(e) => eprintln!("open-mycobot: the Basic's new server port cannot be had: {e}"),
        });
    }
    if let Some(presses) = presses {
        spawn_key_reader(presses.clone())
            .map_err(|e| format!("cannot read the keys on standard input: {e}"))?;
        let mut presser = Presser::new(presses);
        driver = driver.each_pass(move |served: &mut ServedRobot| {
            let now_us = served.robot.now_us();
            if let Some(io) = served.robot.basic_io_mut() {
                presser.apply(now_us, &mut io.buttons);
            }
        });
    }
    let publish = view.is_some();
    let mut collisions_printed = 0;
    driver = driver.observe_every(web::PUBLISH_PERIOD, move |served: &ServedRobot, late| {
        let collisions = served.robot.collisions();
        for (at_ns, collision) in collisions.iter().skip(collisions_printed) {
            println!("{}", collision_line(*at_ns, collision));
        }
        collisions_printed = collisions.len();
        if publish {
            board.publish(Snapshot::of(&served.robot).ran_late(*late));
        }
    });
    driver.run(&stop)?;
    drop(view);
    drop(link);
    let _ = writeln!(std::io::stdout(), "stopped");
    Ok(())
}

/// The bus and servos serving emulated boards (`--emulated-*`): the Atom's bus UART at `atom`,
/// the Basic's if given, and the pseudo-terminal on the front board's host UART. No 3D view
/// and no TCP server: the firmware is the emulator's, and what the arm does is in its servos.
fn serve_emulated(
    cli: &Cli,
    atom: std::net::SocketAddr,
    stop: &AtomicBool,
    pty: PseudoTerminal,
    link: Option<PtyLink>,
) -> Result<(), Box<dyn std::error::Error>> {
    let host = cli
        .emulated_host
        .ok_or("--emulated-host is needed with --emulated-atom")?;
    // The Atom, the bus's master, starts a frame on a line with no byte under way; the Basic
    // waits for the silence it waits for on the real bus.
    let mut buses = vec![(
        Chardev::connect("Atom's bus UART", atom, CONNECT_TIMEOUT, stop)?,
        0,
    )];
    if let Some(basic) = cli.emulated_basic {
        let chardev = Chardev::connect("Basic's bus UART", basic, CONNECT_TIMEOUT, stop)?;
        buses.push((chardev, protocol_core::timing::BUS_QUIET_BEFORE_SEND_US));
    }
    let front_name = if cli.emulated_basic.is_some() {
        "Basic's host UART"
    } else {
        "Atom's host UART"
    };
    let front = Chardev::connect(front_name, host, CONNECT_TIMEOUT, stop)?;
    let mut out = std::io::stdout().lock();
    let boards = if cli.emulated_basic.is_some() {
        "the emulated Basic and Atom"
    } else {
        "the emulated Atom"
    };
    writeln!(
        out,
        "virtual myCobot 280 bus with {boards}: the {} on {}",
        front_name.replace("host UART", "USB serial"),
        pty.slave_path().display()
    )?;
    if let Some(link) = &link {
        writeln!(out, "pty link {}", link.path().display())?;
    }
    let mut arm = EmulatedArm::new(
        RobotConfig::default().seed,
        RobotConfig::default().initial_position_steps,
    );
    for &obstacle in &cli.obstacles {
        arm.add_obstacle(obstacle);
        writeln!(out, "obstacle: {obstacle}")?;
    }
    for &fault in cli.late_replies.iter().chain(&cli.lost_replies) {
        arm.add_reply_fault(fault);
        writeln!(out, "fault: {fault}")?;
    }
    writeln!(out, "ready (Ctrl-C to stop)")?;
    out.flush()?;
    drop(out);

    let robot = EmulatedBoards::new(arm, buses, front);
    RealtimeDriver::new(robot, pty, None).run(stop)?;
    drop(link);
    let _ = writeln!(std::io::stdout(), "stopped");
    Ok(())
}

/// What the virtual robot prints when the Atom detects a collision.
fn collision_line(at_ns: u64, collision: &Collision) -> String {
    format!(
        "collision: joint {} while {}, error {} (load {:.1} %), at {:.3} s; \
         clear_error_information() to move again",
        collision.joint + 1,
        collision.kind.during(),
        collision.code(),
        f64::from(collision.load_permille) / 10.0,
        at_ns as f64 / 1e9
    )
}

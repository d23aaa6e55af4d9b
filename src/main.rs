//! `cargo run --release`: starts the virtual myCobot 280 in real time on a pseudo-terminal
//! (and optionally TCP), powered on with all joints at 0, until Ctrl-C or SIGTERM.

use std::io::Write;
use std::process::ExitCode;

use clap::Parser;
use open_mycobot::host::cli::Cli;
use open_mycobot::host::pty::PseudoTerminal;
use open_mycobot::host::pty_link::PtyLink;
use open_mycobot::host::realtime::{HostLink, RealtimeDriver, stop_on_signals};
use open_mycobot::host::tcp::TcpServer;

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
    let pty = PseudoTerminal::open()?;
    let tcp = cli.tcp.map(TcpServer::bind).transpose()?;
    let link = cli
        .pty_link
        .as_deref()
        .map(|path| PtyLink::create(path, pty.slave_path()))
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

    RealtimeDriver::new(new_robot(), pty, tcp).run(&stop)?;
    drop(link);
    println!("stopped");
    Ok(())
}

fn new_robot() -> impl HostLink {
    StandIn::default()
}

/// TEMPORARY stand-in until `open_mycobot::sim::VirtualRobot` lands: acks every frame.
#[derive(Default)]
struct StandIn {
    now_us: u64,
    decoder: protocol_core::FrameDecoder,
    out: Vec<u8>,
}

impl HostLink for StandIn {
    fn now_us(&self) -> u64 {
        self.now_us
    }
    fn host_write(&mut self, bytes: &[u8]) {
        let out = &mut self.out;
        self.decoder.feed(bytes, |f| {
            out.extend_from_slice(&[0xFE, 0xFE, 0x03, f.cmd(), 0x01, 0xFA]);
        });
    }
    fn host_read(&mut self, out: &mut Vec<u8>) {
        out.append(&mut self.out);
    }
    fn run_until(&mut self, t_us: u64) {
        self.now_us = t_us;
    }
}

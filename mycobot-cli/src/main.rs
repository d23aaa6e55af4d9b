//! `mycobot`: the myCobot 280 from a shell, over its USB serial, its Wi-Fi server or the
//! virtual robot (`mycobot --help`). Each failure is one line on stderr and a non-zero exit.

mod args;
mod commands;
mod link;
mod motion;

use std::process::ExitCode;

use clap::{CommandFactory, Parser};

use crate::args::Cli;
use crate::link::Robot;

fn main() -> ExitCode {
    let cli = Cli::parse();
    if let Some(problem) = cli.link_problem() {
        Cli::command()
            .error(clap::error::ErrorKind::MissingRequiredArgument, problem)
            .exit();
    }
    let result = Robot::open(
        cli.port.as_deref(),
        cli.tcp.as_deref(),
        cli.dialect.into(),
        cli.timeout_ms,
    )
    .and_then(|mut robot| commands::run(&mut robot, &cli.command));
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(failure) => {
            eprintln!("mycobot: {failure}");
            ExitCode::FAILURE
        }
    }
}

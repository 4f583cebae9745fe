//! Argument parsing (clap) and dispatch.

mod converge;
mod theory;
mod verify;

use clap::{Parser, Subcommand};
use langevin_fem::Result;

/// Finite-element Langevin dynamics of thermally fluctuating filaments, with exact
/// references and statistical verification.
#[derive(Debug, Parser)]
#[command(name = "langevin-fem", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Exact results of the theory, printed as one JSON object on stdout.
    Theory(theory::TheoryArgs),
    /// Run verification scenes and write reports.
    Verify(verify::VerifyArgs),
    /// Convergence study of a linear scene over the element count or the time step.
    Converge(converge::ConvergeArgs),
}

/// Parses the command line and runs the command; returns the process exit code.
pub fn run() -> Result<i32> {
    let cli = Cli::parse();
    match cli.command {
        Command::Theory(args) => theory::run(args),
        Command::Verify(args) => verify::run(args),
        Command::Converge(args) => converge::run(args),
    }
}

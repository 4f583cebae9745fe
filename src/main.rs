//! `langevin-fem`: command-line front end. All the work is in the library crate
//! `langevin_fem`; this binary parses arguments, calls it and maps errors to exit codes
//! (0 success, 1 a verification check failed, 2 bad input, 3 a run failed).

mod cli;

fn main() {
    restore_sigpipe();
    match cli::run() {
        Ok(code) => std::process::exit(code),
        Err(err) => {
            eprintln!("error: {err}");
            std::process::exit(err.exit_code());
        }
    }
}

/// Restores the default action of SIGPIPE (which Rust's runtime ignores), so that output
/// into a closed pipe (`langevin-fem scene show NAME | head`) ends the process quietly, as
/// it does for other Unix tools, instead of a panic on the failed write.
fn restore_sigpipe() {
    #[cfg(unix)]
    // SAFETY: called first thing in `main`, before any other thread exists; setting a
    // signal's disposition to its default has no other precondition.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

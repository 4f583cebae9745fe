//! `langevin-fem`: command-line front end. All the work is in the library crate
//! `langevin_fem`; this binary parses arguments, calls it and maps errors to exit codes
//! (0 success, 1 a verification check failed, 2 bad input, 3 a run failed).

mod cli;

fn main() {
    match cli::run() {
        Ok(code) => std::process::exit(code),
        Err(err) => {
            eprintln!("error: {err}");
            std::process::exit(err.exit_code());
        }
    }
}

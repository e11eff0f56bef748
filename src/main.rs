//! `radiosity`: command-line front end. Errors are reported as one line on stderr with a non-zero
//! exit status; user errors never print a panic backtrace.

mod cli;

use clap::Parser;

fn main() -> std::process::ExitCode {
    // Under mpirun (feature `mpi`): MPI is initialised here and finalised when this is dropped.
    #[cfg(feature = "mpi")]
    let _universe = cli::mpi::init();
    let args = cli::Cli::parse();
    match cli::run(args) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            // One line: the chain of causes joined, the outermost first.
            let msg: Vec<String> = e.chain().map(ToString::to_string).collect();
            eprintln!("error: {}", msg.join(": "));
            // A distributed run ends every rank (the others would wait for this one).
            #[cfg(feature = "mpi")]
            cli::mpi::abort_if_distributed();
            std::process::ExitCode::FAILURE
        }
    }
}

//! The `fitbead` binary: parses arguments, calls the library and renders its results and
//! errors. The command-line modules live in `src/cli/` and belong to the binary alone; the
//! library (`src/lib.rs`) never sees them.

mod cli;

use clap::Parser;

fn main() {
    let args = cli::Cli::parse();
    std::process::exit(cli::run(args));
}

//! The `fitbead` binary: parses arguments and hands them to the library's `cli` module.

use clap::Parser;

fn main() {
    let cli = fitbead::cli::Cli::parse();
    std::process::exit(fitbead::cli::run(cli));
}

//! The `fitbead` binary: parses arguments, calls the library and renders its results and
//! errors. The command-line modules live in `src/cli/` and belong to the binary alone; the
//! library (`src/lib.rs`) never sees them.

// `!(x > 0.0)` is deliberate throughout: a NaN must land in the failure branch.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod cli;

fn main() {
    let args = cli::parse();
    std::process::exit(cli::run(args));
}

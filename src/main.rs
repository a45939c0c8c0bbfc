//! The `fitbead` binary: the command line of the library (`fitbead::cli`, built with the
//! default feature `cli`), which parses the arguments, calls the library and renders its
//! results and errors.

fn main() {
    std::process::exit(fitbead::cli::main());
}

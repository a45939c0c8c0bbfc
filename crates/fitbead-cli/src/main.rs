//! The `fitbead` binary: the command line of the library. It parses the arguments, calls the
//! library's commands and writes their results and errors (module `cli`, one module per
//! subcommand).

mod cli;

/// mimalloc in place of the system allocator: the streaming commands hand buffers between
/// threads, which glibc's malloc serialises on many cores (docs/PERFORMANCE.md, "The
/// allocator"). It is built without transparent huge pages, which would keep several times the
/// memory resident.
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() {
    std::process::exit(cli::main());
}

//! The `fitbead` binary: the command line of the library (`fitbead::cli`, built with the
//! default feature `cli`), which parses the arguments, calls the library and renders its
//! results and errors.

/// mimalloc in place of the system allocator: the streaming commands hand buffers between
/// threads, which glibc's malloc serialises on many cores (docs/PERFORMANCE.md, "The
/// allocator"). It is built without transparent huge pages, which would keep several times the
/// memory resident.
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() {
    std::process::exit(fitbead::cli::main());
}

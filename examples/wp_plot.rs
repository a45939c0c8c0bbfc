//! Re-plots a work-precision table written by `fitbead bench --output` without measuring
//! again (the figure's look changes, the measurements stay):
//!
//!     cargo run --release --features bench-internals --example wp_plot -- bench/wp.csv bench/wp.svg "Work-precision, 2000 scenes (seed 1)"

use fitbead::bench_internals::replot;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [csv, svg, title] = args.as_slice() else {
        eprintln!("usage: wp_plot WP.csv OUT.svg TITLE");
        std::process::exit(2);
    };
    let bytes = std::fs::read(csv).unwrap_or_else(|e| {
        eprintln!("{csv}: {e}");
        std::process::exit(2)
    });
    let out = replot(&bytes, title).unwrap_or_else(|e| {
        eprintln!("{csv}: {e}");
        std::process::exit(2)
    });
    if let Err(e) = std::fs::write(svg, out) {
        eprintln!("{svg}: {e}");
        std::process::exit(1);
    }
}

//! The bead problems: K per point (eq 69) against references and at its edges, and the
//! posteriors (calibration by simulation, Jaeger's reparameterisation): `cargo test --release --lib
//! fit::suite`.

mod cross_solvers;
mod gradients;
mod jaeger_posterior;
mod k_contacts;
mod k_edges;
mod k_inversion;
mod k_slope;
mod sbc;

/// A table of tests/reference/ (docs/ACCURACY.md#reference-tables says how each was made):
/// its header and its rows of cells.
fn reference_table(name: &str) -> (Vec<String>, Vec<Vec<String>>) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests")
        .join("reference")
        .join(name);
    let mut r = csv::Reader::from_path(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let h = r.headers().unwrap().iter().map(String::from).collect();
    let rows = r
        .records()
        .map(|x| x.unwrap().iter().map(String::from).collect())
        .collect();
    (h, rows)
}

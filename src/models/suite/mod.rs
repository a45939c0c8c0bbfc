//! The forward models against the paper's figures and tables and against independent
//! references (tests/reference/), and their physical properties: `cargo test --release --lib
//! models::suite`.

mod paper_figures;
mod properties;
mod reference_models;

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

/// The index of column `name` in the header `h`.
fn col(h: &[String], name: &str) -> usize {
    h.iter()
        .position(|c| c == name)
        .unwrap_or_else(|| panic!("missing column {name}: {h:?}"))
}

//! Tests of the streaming engine (`io::stream`) with the row plans of `forward` and `k`,
//! against the golden outputs of `tests/golden/`, and the fits of measurement files whose
//! slopes carry errors against ODRPACK (`slopes`): `cargo test --release --lib pipeline::suite`.

mod csv_ranges;
mod forward_stream;
mod k_stream;
mod slopes;

//! The ensemble sampler on densities with known moments and autocorrelation times: `cargo
//! test --release --lib inverse::suite`.

mod mcmc;

//! The solvers on problems with known answers: the least-squares estimate with its profile
//! intervals (`estimate`) and the ensemble sampler on densities with known moments and
//! autocorrelation times (`mcmc`): `cargo test --release --lib inverse::suite`.

mod estimate;
mod mcmc;
mod odr;

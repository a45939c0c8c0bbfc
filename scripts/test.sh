#!/usr/bin/env bash
# Every test: the Rust suite (`cargo test --release`), then the Python package's suite against
# a wheel built from this checkout and installed in a fresh virtual environment
# (scripts/test_python.sh). .ci/run calls this after the format, lint and documentation gates.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo test --release
# The binary `cargo test` built serves the Python tests (a plain `cargo build` would build it
# again: the tests build with the dev-dependencies' features).
# The wheel builds in the root's target directory here, reusing the dependencies just built
# (nothing else builds beside it in this script).
FITBEAD_BIN_BUILT=1 FITBEAD_WHEEL_TARGET=target scripts/test_python.sh

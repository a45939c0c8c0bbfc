#!/usr/bin/env bash
# The Python package's tests, as CI runs them: a fresh virtual environment (target/python-venv),
# the test dependencies from the package index, `pip install ./python` (which compiles the
# extension against this checkout), then pytest against the command-line binary
# target/release/fitbead (built here unless FITBEAD_BIN_BUILT=1 says it is built).
set -euo pipefail
cd "$(dirname "$0")/.."
venv="${FITBEAD_VENV:-target/python-venv}"
rm -rf "$venv"
python3 -m venv "$venv"
py="$venv/bin/python"
# cairosvg: the second renderer of python/tests/test_figures.py (it needs the system's
# libcairo; without it that one test is skipped, saying why).
"$py" -m pip install --quiet --disable-pip-version-check maturin numpy pytest pandas arviz cairosvg
start=$(date +%s)
"$py" -m pip install --quiet --disable-pip-version-check ./python
echo "pip install ./python: $(($(date +%s) - start)) s"
"$py" -c "import fitbead; print('import fitbead:', fitbead.__version__, 'on', fitbead.threads(), 'threads')"
# .ci/run sets FITBEAD_BIN_BUILT=1 after `cargo test --release` has built the binary (a plain
# `cargo build` would build it again: tests build with the dev-dependencies' features).
if [ "${FITBEAD_BIN_BUILT:-0}" != 1 ]; then
  cargo build --release --bin fitbead
fi
"$py" -m pytest -q -p no:cacheprovider python/tests

#!/usr/bin/env bash
# The Python package's tests, as CI runs them:
# 1. a build environment (target/python-build-venv) with maturin, which builds one abi3 wheel
#    (CPython >= 3.9, manylinux tag checked by maturin) into python/target/wheels; the
#    extension compiles in its own target directory, python/target (python/.cargo/config.toml);
# 2. a fresh test environment (target/python-venv) with the test dependencies (installed while
#    the wheel compiles), where the wheel is installed with cargo off PATH, as on a machine
#    without Rust;
# 3. pytest against the command-line binary target/release/fitbead (built here unless
#    FITBEAD_BIN_BUILT=1 says it is built), with cargo still off PATH: the two-renderer figure
#    tests (test_figures.py, mostly single-threaded rendering) in a second pytest process beside
#    the others, their output shown after.
# FITBEAD_PY_STEP=build does 1 and 2 only, FITBEAD_PY_STEP=test 3 only (on what a build step
# left), so that scripts/test.sh can run other tests between them; the default does all three.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
pipq=(--quiet --disable-pip-version-check)
build_venv="${FITBEAD_BUILD_VENV:-target/python-build-venv}"
venv="${FITBEAD_VENV:-target/python-venv}"

step=${FITBEAD_PY_STEP:-all}
py="$root/$venv/bin/python"
wheel_dir=python/target/wheels

build() {
  if [ ! -x "$build_venv/bin/maturin" ]; then
    python3 -m venv "$build_venv"
    "$build_venv/bin/python" -m pip install "${pipq[@]}" "maturin>=1.7,<2"
  fi

  # The test environment and its dependencies are downloaded and installed while the wheel
  # compiles (the one waits on the network, the other on the CPU); the wheel goes in after both.
  rm -rf "$venv"
  deps_log="$root/target/python-test-deps.log"
  mkdir -p "$root/target"
  (python3 -m venv "$venv" && "$py" -m pip install "${pipq[@]}" -r python/tests/requirements.txt) \
    >"$deps_log" 2>&1 &
  deps_pid=$!

  rm -f "$wheel_dir"/fitbead-*.whl
  start=$(date +%s)
  # FITBEAD_WHEEL_TARGET: the cargo target directory of the wheel's build (default
  # python/target, its own; scripts/test.sh points it at the root's target, whose dependencies
  # `cargo test --release` has just built, when nothing else is building).
  (cd python && CARGO_TARGET_DIR="$root/${FITBEAD_WHEEL_TARGET:-python/target}" \
    "$root/$build_venv/bin/maturin" build --release --quiet \
    --interpreter "$root/$build_venv/bin/python" --out target/wheels)
  wheel=$(ls "$wheel_dir"/fitbead-*.whl)
  echo "wheel: $(basename "$wheel"), $(stat -c %s "$wheel") bytes, built in $(($(date +%s) - start)) s"
  case "$(basename "$wheel")" in
    *-abi3-manylinux*) ;;
    *) echo "the wheel is not an abi3 manylinux wheel: $(basename "$wheel")" >&2; exit 1 ;;
  esac

  if [ "${FITBEAD_BIN_BUILT:-0}" != 1 ]; then
    cargo build --release --bin fitbead
  fi

  if ! wait "$deps_pid"; then
    cat "$deps_log" >&2
    echo "the test environment could not be made (log above)" >&2
    exit 1
  fi
}

run_tests() {
  wheel=$(ls "$wheel_dir"/fitbead-*.whl)
  # PATH without any directory that holds cargo or rustc.
  nocargo=$(printf '%s' "$PATH" | tr ':' '\n' | while read -r d; do
    [ -n "$d" ] && [ ! -x "$d/cargo" ] && [ ! -x "$d/rustc" ] && printf '%s:' "$d"; done)
  nocargo=${nocargo%:}

  PATH="$nocargo" "$py" -m pip install "${pipq[@]}" "$wheel"
  PATH="$nocargo" "$py" -c "import fitbead, shutil; assert shutil.which('cargo') is None; print('import fitbead:', fitbead.__version__, 'on', fitbead.threads(), 'threads, cargo not on PATH')"
  pytest() {
    PATH="$nocargo" FITBEAD_BIN="$root/target/release/fitbead" MPLBACKEND=Agg \
      "$py" -m pytest -q -p no:cacheprovider "$@"
  }
  figures_log="$root/target/pytest-figures.log"
  pytest python/tests/test_figures.py >"$figures_log" 2>&1 &
  figures_pid=$!
  status=0
  pytest --ignore=python/tests/test_figures.py python/tests || status=$?
  figures=0
  wait "$figures_pid" || figures=$?
  echo "-- python/tests/test_figures.py (run beside the others):"
  cat "$figures_log"
  [ "$figures" = 0 ] || status=$figures
  return "$status"
}

case "$step" in
  build) build ;;
  test) run_tests ;;
  all) build; run_tests ;;
  *) echo "FITBEAD_PY_STEP=$step: expected build, test or all" >&2; exit 2 ;;
esac

#!/usr/bin/env bash
# Every test: the Rust suite (every test that `cargo test --release` runs), then the Python
# package's suite against a wheel built from this checkout and installed in a fresh virtual
# environment (scripts/test_python.sh). .ci/run calls this beside its format, lint and
# documentation gates.
#
# What needs no lock of the target directory runs beside what does, so that a small machine's
# cores stay busy:
# 1. every test target is built (`cargo test --release --no-run`), then the doctests run;
# 2. the library's unit tests (computation only: nothing in them is timed) run while the
#    Python wheel compiles;
# 3. the integration tests run alone (some of them time how soon a Ctrl-C stops a run);
# 4. the Python suite.
# Each step prints when it starts (seconds since the start).
set -euo pipefail
cd "$(dirname "$0")/.."
step() {
  echo "== test.sh ${SECONDS}s: $*"
  "$@"
}
# The tests build with the release profile's optimisation level but without its link-time
# optimisation and single codegen unit, which serve the published binary's speed, not the
# tests (floating-point results do not depend on them: Rust never contracts or reassociates
# floating-point operations); exported, so the Python wheel's build shares the setting. `off`,
# not `false`: `false` still runs ThinLTO across each crate's 16 codegen units, which took
# 23 of the library's 53 s of compilation; a fresh `cargo test --release --no-run` takes 231 s
# with `off` against 282 s with `false`, and the tests run 42.0 and 70.1 s against 38.5 and
# 69.1 s (unit and integration tests; 2-core AMD EPYC, idle, 2026-12-06).
export CARGO_PROFILE_RELEASE_LTO=off CARGO_PROFILE_RELEASE_CODEGEN_UNITS=16
mkdir -p target
artifacts=target/test-executables.json
echo "== test.sh ${SECONDS}s: cargo test --release --no-run"
cargo test --release --no-run --message-format=json-render-diagnostics >"$artifacts"
# The test executables `cargo test` would run, as "KIND NAME PATH" lines (KIND: lib, bin or
# test), the library's first.
mapfile -t exes < <(python3 - "$artifacts" <<'PY'
import json, sys
rows = []
for line in open(sys.argv[1]):
    m = json.loads(line)
    if m.get("reason") == "compiler-artifact" and m.get("executable") and m["profile"]["test"]:
        t = m["target"]
        rows.append((t["kind"][0] != "lib", t["kind"][0], t["name"], m["executable"]))
for _, kind, name, path in sorted(rows):
    print(kind, name, path)
PY
)
[ "${#exes[@]}" -gt 0 ] || { echo "no test executables were built" >&2; exit 1; }
step cargo test --release --doc

read -r kind name lib_exe <<<"${exes[0]}"
[ "$kind" = lib ] || { echo "no unit tests of the library were built" >&2; exit 1; }
lib_log=target/test-lib.log
echo "== test.sh ${SECONDS}s: unit tests of the library ($lib_exe), beside the wheel's build"
"$lib_exe" >"$lib_log" 2>&1 &
lib_pid=$!
# The binary `cargo test` built serves the Python tests; the wheel builds in the root's target
# directory, reusing the dependencies just built.
wheel=0
FITBEAD_PY_STEP=build FITBEAD_BIN_BUILT=1 FITBEAD_WHEEL_TARGET=target \
  step scripts/test_python.sh || wheel=$?
lib=0
wait "$lib_pid" || lib=$?
echo "== test.sh ${SECONDS}s: unit tests of the library ended (exit $lib):"
cat "$lib_log"
[ "$lib" = 0 ] || exit "$lib"
[ "$wheel" = 0 ] || exit "$wheel"

for e in "${exes[@]:1}"; do
  read -r kind name exe <<<"$e"
  step "$exe"
done
FITBEAD_PY_STEP=test step scripts/test_python.sh
echo "== test.sh ${SECONDS}s: every test passed"

#!/usr/bin/env bash
# Whole-process `fitbead k` against its scipy peer (scripts/peer_k.py), µs per row.
#
# Usage: scripts/bench_k_peer.sh N M [MS]
#   N   rows of the random measured file for fitbead (python3 scripts/gen_measurements.py N 1)
#   M   rows of the same file for the peer, stick (its first M rows)
#   MS  rows for the peer, stickslip (default M / 10, at least 1)
# Builds nothing: runs target/release/fitbead (override with FITBEAD=path) and the peer under
# PYTHON (default /tmp/peervenv/bin/python, with scipy and numpy). fitbead runs single-threaded
# (RAYON_NUM_THREADS=1) on the whole file, median of 5 runs (stick) and 3 (stickslip), wall time
# by python3's perf_counter around each run (to the microsecond: /usr/bin/time's hundredths of
# a second are a tenth of a µs per row at 100,000 rows); the peer on the first M (MS) rows, median of 2. Prints µs per row of each,
# the ratio peer / fitbead, and `uptime` before and after: a figure taken at a load above ~1.2
# on this 2-core machine is not a measurement. Both are whole-process times: the peer's include
# its start (importing scipy, about half a second), so take M large enough (thousands of rows)
# for that to be small beside the loop (the peer also prints its loop alone on stderr).
set -euo pipefail
N=${1:?usage: bench_k_peer.sh N M [MS]}
M=${2:?usage: bench_k_peer.sh N M [MS]}
MS=${3:-$(( M / 10 > 0 ? M / 10 : 1 ))}
here=$(cd "$(dirname "$0")/.." && pwd)
FITBEAD=${FITBEAD:-$here/target/release/fitbead}
PYTHON=${PYTHON:-/tmp/peervenv/bin/python}
[ -x "$FITBEAD" ] || { echo "no fitbead binary at $FITBEAD (cargo build --release)" >&2; exit 2; }
"$PYTHON" -c 'import scipy, numpy' 2>/dev/null || {
  echo "$PYTHON lacks scipy/numpy: python3 -m venv /tmp/peervenv && /tmp/peervenv/bin/pip install scipy numpy" >&2
  exit 2
}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
python3 "$here/scripts/gen_measurements.py" "$N" 1 > "$work/m.csv"

# Median wall seconds of REPS runs of the command after it (its stdout discarded; its stderr
# shown, and the script stopped, when it fails). REMOVE_BEFORE=FILE removes FILE before each
# run, untimed: a run that replaced the last run's output would time the freeing of its blocks
# in the final rename.
median_of() {
  python3 - "$@" <<'PY' || exit 1
import os, statistics, subprocess, sys, time
reps, cmd = int(sys.argv[1]), sys.argv[2:]
old = os.environ.get("REMOVE_BEFORE")
ts = []
for _ in range(reps):
    if old and os.path.exists(old):
        os.remove(old)
    t = time.perf_counter()
    r = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    ts.append(time.perf_counter() - t)
    if r.returncode != 0:
        sys.stderr.write(r.stderr.decode(errors="replace"))
        sys.exit(1)
print(f"{statistics.median(ts):.6f}")
PY
}

echo "uptime before: $(uptime)"
for model in stick stickslip; do
  if [ "$model" = stick ]; then reps=5; rows=$M; else reps=3; rows=$MS; fi
  fb=$(REMOVE_BEFORE="$work/k.csv" median_of "$reps" env RAYON_NUM_THREADS=1 "$FITBEAD" k --model "$model" "$work/m.csv" --output "$work/k.csv")
  pe=$(median_of 2 "$PYTHON" "$here/scripts/peer_k.py" "$model" "$work/m.csv" "$rows")
  awk -v m="$model" -v n="$N" -v r="$rows" -v fb="$fb" -v pe="$pe" 'BEGIN {
    f = 1e6 * fb / n; p = 1e6 * pe / r
    printf "%-9s fitbead %10.3f us/row (%d rows, %.4f s)   peer %10.1f us/row (%d rows, %.3f s)   ratio %.0f\n", m, f, n, fb, p, r, pe, (f > 0 ? p / f : 0)
  }'
done
echo "uptime after:  $(uptime)"

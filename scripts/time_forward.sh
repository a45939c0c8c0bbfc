#!/bin/bash
# Times `fitbead forward --model stick` on a scenes file, N runs
# (docs/PERFORMANCE.md, "Batch forward").
# usage: scripts/time_forward.sh BIN INPUT N [OUTPUT]   (OUTPUT default out.csv)
# Prints per run: wall s, peak RSS KB, user s, sys s, and the machine's CPU use (all cores)
# in the second before and after the run; a run is "idle" when both are <= 8 %, else "busy"
# (another process was using a core, so the time is an upper bound).
BIN=${1:-target/release/fitbead}; INPUT=${2:-big.csv}; N=${3:-7}
OUT=${4:-out.csv}
busy() {
  read -r _ a b c d e f g _ </proc/stat; t1=$((a + b + c + d + e + f + g)); i1=$d
  sleep 1
  read -r _ a b c d e f g _ </proc/stat; t2=$((a + b + c + d + e + f + g)); i2=$d
  echo $((100 - 100 * (i2 - i1) / (t2 - t1)))
}
for _ in $(seq "$N"); do
  b1=$(busy)
  t=$(/usr/bin/time -f "%e s  %M KB  user %U s  sys %S s" "$BIN" forward --model stick \
    --input "$INPUT" --output "$OUT" 2>&1 >/dev/null)
  b2=$(busy)
  tag=idle; { [ "$b1" -gt 8 ] || [ "$b2" -gt 8 ]; } && tag=busy
  echo "$t  cpu before ${b1}% after ${b2}%  $tag"
done

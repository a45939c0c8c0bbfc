#!/usr/bin/env bash
# Side by side, in one session: two builds of fitbead on the commands whose thread scaling
# docs/PERFORMANCE.md tracks (`k --model stick` on 5,000,000 rows, `forward --model stick` on
# 1,000,000 rows), at 1 and 16 threads on all cores, then at 1 and 2 threads pinned to two
# cores (taskset -c 0,1). Whole processes, `/usr/bin/time`, output to a file on local disk,
# REPS runs each (default 3), the median printed with every run. The inputs are made by the
# second binary's `simulate` with the seeds scripts/scaling.sh uses.
#
# Usage: scripts/scaling_vs.sh BASE_BINARY NEW_BINARY
set -u
base=$(cd "$(dirname "$1")" && pwd)/$(basename "$1")
new=$(cd "$(dirname "$2")" && pwd)/$(basename "$2")
reps=${REPS:-3}
work=${WORK:-$(mktemp -d)}
mkdir -p "$work"
cd "$work" || exit 2
series20=$(python3 -c "print(','.join(f'{0.8 + 0.11 * k:.2f}' for k in range(20)))")
[ -f k_stick.csv ] || "$new" simulate --model stick --series "$series20" --points 250000 --seed 1 \
  --output k_stick.csv || exit 2
[ -f forward_stick.csv ] || "$new" simulate --model stick --series 0.8,1,1.6,2 --points 250000 \
  --seed 2 --output forward_stick.csv || exit 2
head -n 1000001 k_stick.csv > k_stick_1m.csv
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2-), $(date -u '+%Y-%m-%d %H:%M UTC')"
run() { # label pin threads command...
  local label=$1 pin=$2 t=$3
  shift 3
  local walls=()
  for _ in $(seq "$reps"); do
    local m
    if [ "$pin" = all ]; then
      m=$(RAYON_NUM_THREADS=$t /usr/bin/time -f "%e %U %M" "$@" 2>&1 >/dev/null | tail -n 1)
    else
      m=$(RAYON_NUM_THREADS=$t taskset -c "$pin" /usr/bin/time -f "%e %U %M" "$@" 2>&1 >/dev/null | tail -n 1)
    fi
    walls+=("$m")
  done
  local med
  med=$(printf '%s\n' "${walls[@]}" | awk '{print $1}' | sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}')
  echo "$label | cores $pin | $t thr | median $med s | runs (wall user maxrss_kB): $(printf '%s; ' "${walls[@]}")"
}
# The two builds alternate at every setting, so that drift of the machine hits both alike.
pick() { if [ "$1" = new ]; then echo "$new"; else echo "$base"; fi; }
for t in 1 16; do
  for which in base new; do
    run "$which k stick 5M" all "$t" "$(pick $which)" k --model stick --input k_stick.csv --output out.csv
    run "$which forward stick 1M" all "$t" "$(pick $which)" forward --model stick --input forward_stick.csv --output out.csv
  done
done
for t in 1 2; do
  for which in base new; do
    run "$which k stick 1M" 0,1 "$t" "$(pick $which)" k --model stick --input k_stick_1m.csv --output out.csv
    run "$which forward stick 1M" 0,1 "$t" "$(pick $which)" forward --model stick --input forward_stick.csv --output out.csv
  done
done
rm -f out.csv

#!/usr/bin/env bash
# Thread scaling of the commands that stream or fit (docs/PERFORMANCE.md, "Thread scaling"):
# whole-process wall time (median of REPS runs) and peak RSS of each command at each thread
# count (RAYON_NUM_THREADS), printed as a Markdown table with the machine's core count, CPU
# model and the date. Self-contained: the inputs are made by the binary's own `simulate`
# (the report uses the embedded data set); bash and python3 only, no network.
#
# Usage: scripts/scaling.sh BINARY [THREADS...]        (default threads: 1 2 4 8 16)
#   REPS=3         runs per cell (the median is reported)
#   WORK=DIR       where inputs and outputs go (default: a fresh temporary directory,
#                  removed at the end); inputs already there are used as they are
#   SMALL=1        inputs 100 times smaller (to try the script itself)
#   ONLY=0,1       run only these commands (their indices in the table, from 0)
#   NO_TIME=1      time with python3 even where /usr/bin/time exists
#   SINK=null      the streaming commands write to standard output, discarded, instead of
#                  --output out.csv (the report always writes its directory)
set -u
bin=$(cd "$(dirname "$1")" && pwd)/$(basename "$1")
shift
threads=("$@")
[ ${#threads[@]} -eq 0 ] && threads=(1 2 4 8 16)
reps=${REPS:-3}
div=1
[ "${SMALL:-0}" = 1 ] && div=100
if [ -n "${WORK:-}" ]; then
  work=$WORK
  mkdir -p "$work"
else
  work=$(mktemp -d)
  trap 'rm -rf "$work"' EXIT
fi
cd "$work" || exit 2

# --- inputs (the same for every binary: fixed seeds) ----------------------------------
series20=$(python3 -c "print(','.join(f'{0.8 + 0.11 * k:.2f}' for k in range(20)))")
[ -f k_stick.csv ] || "$bin" simulate --model stick --series "$series20" --points $((250000 / div)) --seed 1 \
  --output k_stick.csv || exit 2
[ -f forward_stick.csv ] || "$bin" simulate --model stick --series 0.8,1,1.6,2 --points $((250000 / div)) --seed 2 \
  --output forward_stick.csv || exit 2
[ -f k_stickslip.csv ] || "$bin" simulate --model stickslip --series "$series20" --points $((5000 / div)) --seed 3 \
  --output k_stickslip.csv || exit 2
[ -f forward_contact.csv ] || "$bin" simulate --model stick --series 0.8,1,1.6,2 --points $((25000 / div)) --seed 4 \
  --output forward_contact.csv || exit 2
[ -f klaw_stickslip.csv ] || cp k_stickslip.csv klaw_stickslip.csv

# --- runs -----------------------------------------------------------------------------
names=(
  "k --model stick ($((5000000 / div)) rows)"
  "forward --model stick ($((1000000 / div)) rows)"
  "k --model stickslip ($((100000 / div)) rows)"
  "forward --model contact ($((100000 / div)) rows)"
  "klaw --model stickslip ($((100000 / div)) points)"
  "report --method mcmc (shipped data)"
)
cmds=(
  "k --model stick --input k_stick.csv --output out.csv"
  "forward --model stick --input forward_stick.csv --output out.csv"
  "k --model stickslip --input k_stickslip.csv --output out.csv"
  "forward --model contact --input forward_contact.csv --output out.csv"
  "klaw --model stickslip --input klaw_stickslip.csv --output out.csv"
  "report --method mcmc --out-dir report_out"
)
if [ "${SINK:-file}" = null ]; then
  for i in "${!cmds[@]}"; do cmds[$i]=${cmds[$i]% --output out.csv}; done
fi
have_time=0
[ -x /usr/bin/time ] && [ "${NO_TIME:-0}" != 1 ] && have_time=1
results=$work/results.tsv
: > "$results"
for i in "${!cmds[@]}"; do
  if [ -n "${ONLY:-}" ] && [[ ",$ONLY," != *",$i,"* ]]; then continue; fi
  for t in "${threads[@]}"; do
    for r in $(seq "$reps"); do
      # Every run writes a new file: replacing an existing one makes the final rename free
      # the old file's blocks, which on ext4 took 0.4-0.7 s for k's 1.6 GB output.
      rm -rf out.csv report_out
      # shellcheck disable=SC2086
      if [ $have_time = 1 ]; then
        m=$(RAYON_NUM_THREADS=$t /usr/bin/time -f "%e %M" "$bin" ${cmds[$i]} 2>&1 >/dev/null |
          tail -n 1)
      else
        # No /usr/bin/time: python3 times the child and reads its peak RSS (KiB on Linux).
        m=$(RAYON_NUM_THREADS=$t python3 -c '
import resource, subprocess, sys, time
s = time.perf_counter()
subprocess.run(sys.argv[1:], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
e = time.perf_counter()
print(f"{e - s:.2f} {resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss}")
' "$bin" ${cmds[$i]})
      fi
      echo "$i	$t	$r	$m" >> "$results"
      echo "  ${names[$i]}, $t threads, run $r: $m" >&2
    done
  done
done

# --- table ----------------------------------------------------------------------------
cpu=$(grep -m1 'model name' /proc/cpuinfo 2>/dev/null | cut -d: -f2- | sed 's/^ *//')
python3 - "$results" "$(nproc)" "${cpu:-unknown}" "$(date -u '+%Y-%m-%d %H:%M UTC')" \
  "$("$bin" --version 2>/dev/null | head -n 1)" "$reps" "${threads[*]}" "${names[@]}" <<'EOF'
import statistics, sys
path, nproc, cpu, date, version, reps, threads = sys.argv[1:8]
names = sys.argv[8:]
threads = threads.split()
cells = {}
for line in open(path):
    i, t, _, rest = line.rstrip("\n").split("\t")
    parts = rest.split()
    wall = float(parts[0]) if parts else float("nan")
    rss = parts[1] if len(parts) > 1 else "-"
    cells.setdefault((int(i), t), []).append((wall, rss))
print(f"Machine: {nproc} cores (nproc), {cpu}; {date}; {version}.")
print(f"Whole-process wall time, median of {reps} runs (s), and peak RSS (MB, the largest "
      "of the runs); threads set by RAYON_NUM_THREADS.")
print()
print("| command | " + " | ".join(f"{t} thr" for t in threads) + f" | speed-up {threads[0]}→{threads[-1]} |")
print("|---|" + "---|" * len(threads) + "---|")
for i, name in enumerate(names):
    row, walls = [], []
    for t in threads:
        runs = cells.get((i, t), [])
        if not runs:
            row.append("–")
            walls.append(None)
            continue
        w = statistics.median(r[0] for r in runs)
        rss = [int(r[1]) for r in runs if r[1].isdigit()]
        mb = f", {max(rss) / 1024:.0f} MB" if rss else ""
        row.append(f"{w:.2f} s{mb}")
        walls.append(w)
    up = f"{walls[0] / walls[-1]:.1f}×" if walls[0] and walls[-1] else "–"
    print(f"| `{name}` | " + " | ".join(row) + f" | {up} |")
EOF

#!/usr/bin/env bash
# Byte identity of the non-streaming commands between two binaries: for every case, stdout,
# stderr, the exit code and every file the run writes in its working directory. The cases
# cover klaw, jan and jaeger (least squares and MCMC, every output file, their errors),
# report (lsq, mcmc, PDF figures), design, simulate, regimes and bench (its timing columns
# blanked). `scripts/same_stream.sh` covers forward and k.
#
# Usage: scripts/same_commands.sh OLD_BINARY NEW_BINARY [WORKDIR]
# Prints one line per differing case and a count; exits 1 when any case differs.
set -u
work=${3:-/tmp/same_commands}
here=$(cd "$(dirname "$0")/.." && pwd)
rm -rf "$work"
mkdir -p "$work/in" "$work/bin/old" "$work/bin/new"
# Both binaries under the same name, which their messages quote.
cp "$1" "$work/bin/old/fitbead"
cp "$2" "$work/bin/new/fitbead"
old=$work/bin/old/fitbead
new=$work/bin/new/fitbead
in=$work/in
cp "$here/data/default.csv" "$in/default.csv"
cp "$here/data/virtual/md_ristow.csv" "$in/md_ristow.csv"
head -5 "$here/data/virtual/md_ristow.csv" >"$in/md5.csv"
"$old" simulate --model stickslip --series 0.8,1,1.6 --points 8 --seed 4 --noise 0.05 \
  >"$in/sim.csv" 2>/dev/null
"$old" simulate --model stick --series 0.8,1 --points 6 --seed 5 >"$in/nosigma.csv" 2>/dev/null
# Slip-model data with one point of sim.csv that the slip model cannot make steady.
"$old" simulate --model slip --series 0.8,1 --points 6 --seed 6 >"$in/slip.csv" 2>/dev/null
sed -n 18p "$in/sim.csv" >>"$in/slip.csv"
python3 - "$in" <<'EOF'
import sys, os
d = sys.argv[1]
rows = open(os.path.join(d, "sim.csv")).read().splitlines()
head, body = rows[0], rows[1:]
# sigma_v dropped from the rows: unit weights.
open(os.path.join(d, "bad.csv"), "w").write(head + "\n" + body[0] + "\n1,2\n")
EOF

# One case per line: NAME<TAB>ARGUMENTS (split by the shell; $in is the inputs' folder).
cases=$(cat <<EOF
klaw_lsq	klaw --model stickslip $in/sim.csv --output p.csv --output-stats s.csv --plot f.svg
klaw_lsq_report	klaw --model stick $in/default.csv
klaw_lsq_png	klaw --model stick --law free-per-series $in/sim.csv --output p.csv --plot f.png
klaw_impact	klaw --model stick --law impact $in/sim.csv
klaw_auto_skip	klaw --model auto --skip-unsteady $in/slip.csv
klaw_noprofile	klaw --model stick --no-profile --level 0.9 $in/sim.csv --output - --output-stats s.csv
klaw_auto	klaw --model auto $in/sim.csv --output p.csv --output-stats s.csv
klaw_auto_tol	klaw --model auto --tol 1e-6 $in/default.csv
klaw_unsteady	klaw --model slip $in/default.csv
klaw_skip	klaw --model slip --skip-unsteady $in/slip.csv --output p.csv --output-stats s.csv --plot f.svg
klaw_skip_report	klaw --model slip --skip-unsteady --law free-per-series $in/slip.csv
klaw_skip_empty_box	klaw --model slip --skip-unsteady $in/default.csv
klaw_skip_free	klaw --model slip --law free-per-series --skip-unsteady $in/default.csv --output p.csv --plot f.svg
klaw_skip_mcmc	klaw --model slip --skip-unsteady --method mcmc --min-ess 100 --max-steps 2000 $in/slip.csv --output p.csv --output-stats s.csv
klaw_mcmc	klaw --model stick --method mcmc --min-ess 150 --max-steps 3000 --seed 3 $in/sim.csv --output p.csv --output-stats s.csv --draws d.csv --plot c.svg
klaw_mcmc_report	klaw --model stick --law free-per-series --method mcmc --min-ess 100 --max-steps 2000 --thin 2 --walkers 36 $in/sim.csv
klaw_mcmc_prior	klaw --model stick --method mcmc --min-ess 100 --max-steps 2000 --prior 'c=normal(0.5,0.1)' --fit-scatter $in/sim.csv --output p.csv --draws -
klaw_mcmc_cap	klaw --model stick --method mcmc --max-steps 50 $in/sim.csv --output p.csv --output-stats s.csv
klaw_prior_bad	klaw --model stick --method mcmc --prior zz=flat $in/sim.csv
klaw_prior_outside	klaw --model stick --method mcmc --prior 'c=uniform(5,6)' $in/sim.csv
klaw_lsq_mcmcflag	klaw --model stick --seed 3 $in/sim.csv
klaw_impact_mcmc	klaw --model stick --law impact --method mcmc $in/sim.csv
klaw_bad	klaw --model stick $in/bad.csv
klaw_nosigma	klaw --model stick $in/nosigma.csv --output p.csv --output-stats s.csv
klaw_rho	klaw --model stickslip --rho 0.5 --f 0.2 $in/default.csv --output p.csv
jan_lsq	jan $in/default.csv --output p.csv --output-stats s.csv --plot f.svg
jan_report	jan $in/sim.csv
jan_mcmc	jan $in/default.csv --method mcmc --min-ess 100 --max-steps 2000 --output p.csv --output-stats s.csv --draws d.csv --plot c.svg
jan_fail	jan $in/bad.csv
jaeger_lsq	jaeger $in/default.csv --output p.csv --output-stats s.csv --plot f.pdf
jaeger_lower	jaeger --branch lower $in/sim.csv
jaeger_mcmc	jaeger $in/default.csv --method mcmc --min-ess 100 --max-steps 2000 --output - --draws d.csv
report_lsq	report $in/sim.csv --out-dir r
report_default	report --out-dir r
report_pdf	report $in/default.csv --out-dir r --format all --figure-width single
report_mcmc	report $in/sim.csv --out-dir r --method mcmc --min-ess 100 --max-steps 2000
design_d	design --model stick --law c=0.5 --series 0.8,1.6 --points 5 --output d.csv --plot d.svg
design_t	design --model stick --vs slip --criterion t --series 1 --points 4 --plot t.svg
design_c	design --model stickslip --criterion c --target c --series 1,2 --total 9 --output d.csv
design_bayes	design --model stick --prior 'c=normal(0.5,0.05)' --draws 8 --series 1 --points 4 --output d.csv --plot -
design_jaeger	design --fit jaeger --series 1 --points 6 --noise abs=0.01
simulate	simulate --model contact --series 0.8,1.2 --points 5 --seed 2 --noise 0.03
simulate_md	simulate --model md --series 0.8 --points 3 --seed 2
forward_md	forward --model md --input $in/md_ristow.csv --output o.csv
forward_md_check	forward --model md --check-step --md-preset steel --input $in/md5.csv
forward_md_bad	forward --model md --input $in/default.csv --beads 0
regimes	regimes --law c=0.4 --xi 0.5,1,2
EOF
)

run_case() {
  local bin=$1 dir=$2 args=$3
  mkdir -p "$dir/files"
  (cd "$dir/files" && eval "set -- $args" && "$bin" "$@" >../stdout 2>../stderr; echo $? >../rc)
}

differ=0
total=0
while IFS=$'\t' read -r name args; do
  [ -n "$name" ] || continue
  total=$((total + 1))
  run_case "$old" "$work/old/$name" "$args"
  run_case "$new" "$work/new/$name" "$args"
  # A report's manifest names the process and the time of its run: those lines aside.
  for m in "$work"/old/"$name"/files/*/.fitbead.manifest "$work"/new/"$name"/files/*/.fitbead.manifest; do
    [ -f "$m" ] && sed -i '/^run fitbead/d' "$m"
  done
  # A PDF's resource dictionaries come in an order that varies from process to process
  # (svg2pdf): its lines are compared as a sorted list.
  find "$work/old/$name" "$work/new/$name" -name '*.pdf' | while read -r f; do
    LC_ALL=C sort "$f" -o "$f"
  done
  if ! diff -r -q "$work/old/$name" "$work/new/$name" >/dev/null 2>&1; then
    differ=$((differ + 1))
    echo "differs: $name ($args)"
    diff -r -q "$work/old/$name" "$work/new/$name" | sed 's/^/  /'
  fi
done <<<"$cases"

# bench: its timing columns vary from run to run; every other column must agree.
total=$((total + 1))
for b in old new; do
  bin=$old
  [ $b = new ] && bin=$new
  mkdir -p "$work/$b/bench"
  (cd "$work/$b/bench" && "$bin" bench --scenes 40 --seed 2 --output b.csv >stdout 2>stderr; echo $? >rc)
  python3 - "$work/$b/bench/b.csv" <<'EOF'
import csv, sys
p = sys.argv[1]
rows = list(csv.reader(open(p)))
keep = [i for i, c in enumerate(rows[0]) if "time" not in c and "ns" not in c and "speed" not in c]
with open(p + ".cmp", "w") as f:
    for r in rows:
        f.write(",".join(r[i] for i in keep) + "\n")
EOF
done
# Its summary on stderr quotes timings, and the cheapest method they pick: the words
# around them must agree.
for b in old new; do
  sed -E 's/[0-9]+ ns/N ns/g; s/reference[)]: [^,]+,/reference): M,/' "$work/$b/bench/stderr" >"$work/$b/bench/stderr.cmp"
done
for f in rc stdout stderr.cmp b.csv.cmp; do
  if ! cmp -s "$work/old/bench/$f" "$work/new/bench/$f"; then
    differ=$((differ + 1))
    echo "differs: bench ($f)"
  fi
done
echo "$differ of $total cases differ"
[ "$differ" = 0 ]

#!/usr/bin/env bash
# Rewrites the golden outputs of `fitbead forward` from a release build, for a change that is
# meant to move the numbers (say why in CHANGELOG.md). Usage: tests/golden/forward/regenerate.sh
set -euo pipefail
cd "$(dirname "$0")/../../.."
cargo build --release --bin fitbead -q
B=target/release/fitbead
G=tests/golden/forward
flags() {
  case $1 in
    stick) echo "--model stick" ;;
    stick_cos2a_rho0.5) echo "--model stick --K cos2a --rho 0.5" ;;
    stick-approx) echo "--model stick-approx" ;;
    slip) echo "--model slip" ;;
    slip-approx) echo "--model slip-approx" ;;
    stickslip_f0.3) echo "--model stickslip --f 0.3" ;;
    contact_keep) echo "--model contact --spin keep" ;;
    jan) echo "--model jan" ;;
    jaeger_upper) echo "--model jaeger --a1 0.05 --a2 0.4 --a3 1.5" ;;
    jaeger_lower) echo "--model jaeger --a1 0.1 --a2 2 --a3 0.3 --branch lower" ;;
    auto_tol1e-8) echo "--model auto --tol 1e-8" ;;
  esac
}
for set in default md_ristow generated; do
  case $set in
    default) in=data/default.csv ;;
    md_ristow) in=data/virtual/md_ristow.csv ;;
    generated) in=$G/generated/input.csv ;;
  esac
  for f in "$G/$set"/*.csv; do
    name=$(basename "$f" .csv)
    [ "$name" = input ] && continue
    # shellcheck disable=SC2046
    "$B" forward $(flags "$name") --input "$in" --output "$f"
  done
done
printf 'xi,delta_deg\n1,12\n' | "$B" forward --model stick --input /dev/stdin --output $G/single_scene.csv

#!/usr/bin/env bash
# Byte identity of the streaming commands between two binaries: stdout, stderr, exit code and
# the --output file (or its absence) of `forward` and `k` on generated, shipped and bad
# inputs, each run at 1 thread and at the machine's default.
#
# Usage: scripts/same_stream.sh OLD_BINARY NEW_BINARY [WORKDIR] [--big]
#   REUSE=1 keeps the outputs of an earlier run in WORKDIR (of binaries of the same names).
#   The new binary's outputs of a case that does not differ are removed (they are the old
#   binary's, byte for byte; the old binary's stay for REUSE): KEEP=1 keeps them too. The
#   outputs take several GB (about 3 GB a binary without --big); the last line gives their
#   size.
#   --big adds the large inputs (k stick on 5,000,000 simulated rows, forward stick on
#   1,000,000), minutes of work.
# Prints one line per differing case and a count; exits 1 when any case differs. With KEEP=1,
# scripts/same_stream_columns.py lists which cells of the differing cases changed, and by how much.
set -u
old=$1
new=$2
work=${3:-/tmp/same_stream}
big=0
for a in "$@"; do [ "$a" = --big ] && big=1; done
here=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$work/in" "$work/out"
cd "$work" || exit 2
in=$work/in

# --- inputs --------------------------------------------------------------------------
python3 "$here/scripts/gen_measurements.py" 100000 1 > "$in/meas.csv"
"$old" simulate --model stick --series 0.8,1,1.6,2 --points 25000 --seed 3 > "$in/sim100k.csv"
cp "$here/data/default.csv" "$in/default.csv"
cp "$here/data/virtual/md_ristow.csv" "$in/md_ristow.csv"
python3 - "$in" <<'EOF'
import sys, os
d = sys.argv[1]
meas = open(os.path.join(d, "meas.csv"), "rb").read()
lines = meas.split(b"\n")
head, rows = lines[0], [l for l in lines[1:] if l]
def w(name, data):
    open(os.path.join(d, name), "wb").write(data)
def rows_with(i, row):
    r = list(rows); r[i] = row; return b"\n".join([head] + r) + b"\n"
w("malformed_early.csv", rows_with(2, b"1,2,3"))
w("malformed_late.csv", rows_with(90000, b"1,2,3,4,5,6,7,8,9,10"))
bad = rows[0].split(b","); bad[3] = b"abc"
w("bad_row1.csv", rows_with(0, b",".join(bad)))
bad = rows[70000].split(b","); bad[2] = b"nan"
w("bad_late.csv", rows_with(70000, b",".join(bad)))
w("bad_then_malformed.csv", rows_with(50000, b",".join(bad)).replace(rows[80000] + b"\n", b"x\n"))
w("crlf.csv", meas.replace(b"\n", b"\r\n"))
w("crlf_bad.csv", rows_with(60000, b",".join(bad)).replace(b"\n", b"\r\n"))
w("crlf_malformed.csv", rows_with(60000, b"1,2").replace(b"\n", b"\r\n"))
w("cr_only.csv", meas.replace(b"\n", b"\r"))
w("bom.csv", b"\xef\xbb\xbf" + meas)
w("bom_quoted_header.csv", b"\xef\xbb\xbf\"series\"" + meas[len(b"series"):])
w("empty.csv", b"")
w("whitespace.csv", b"  \n\n")
w("header_only.csv", head + b"\n")
w("header_only_nonl.csv", head)
w("no_final_newline.csv", meas.rstrip(b"\n"))
w("blank_lines.csv", meas.replace(b"\n", b"\n\n", 40000).replace(b"\n", b"\n \n", 3))
# quoted cells holding newlines, commas and quotes in the pass-through id column, spread
# over the file
q = []
for i, r in enumerate(rows):
    c = r.split(b",")
    if i % 997 == 5 and len(c) == 8:
        c[7] = b'"multi\nline, ""quoted""\r\nid ' + str(i).encode() + b'"'
        r = b",".join(c)
    q.append(r)
w("quoted_newlines.csv", b"\n".join([head] + q) + b"\n")
w("quoted_newlines_bad.csv", b"\n".join([head] + q[:80000] + [q[80000].replace(b",", b",x", 1)] + q[80001:]) + b"\n")
w("unterminated.csv", b"\n".join([head] + rows[:50000] + [rows[50000][:-3] + b',"open'] + rows[50001:]) + b"\n")
w("unterminated_end.csv", meas + rows[5] + b',"open\n')
w("bad_utf8.csv", rows_with(65000, rows[65000] + b"\xff\xfe"))
w("bad_utf8_early.csv", rows_with(1, rows[1] + b"\xc3"))
w("bom_midline.csv", meas.replace(b"\n", b"\n\xef\xbb\xbf", 1).replace(b"\n" + rows[1000], b"\n\xef\xbb\xbf" + rows[1000]))
w("ragged_blank.csv", rows_with(30000, b"   "))
w("missing_col.csv", meas.replace(b"delta_deg", b"delta", 1))
w("missing_col_malformed.csv", rows_with(99000, b"1").replace(b"delta_deg", b"delta", 1))
w("header_dup.csv", meas.replace(b"sigma_v", b"v", 1))
w("semicolon.csv", meas.replace(b",", b";"))
w("only_blank_rows.csv", head + b"\n\n\n")
EOF
if [ $big = 1 ]; then
  [ -f "$in/k5m.csv" ] || "$old" simulate --model stick --series "$(python3 -c "print(','.join(f'{0.8 + 0.11 * k:.2f}' for k in range(20)))")" --points 250000 --seed 5 --output "$in/k5m.csv"
  [ -f "$in/f1m.csv" ] || "$old" simulate --model stick --series 0.8,1,1.6,2 --points 250000 --seed 6 > "$in/f1m.csv"
  [ -f "$in/k5m_bad.csv" ] || python3 - "$in" <<'EOF'
import sys, os
d = sys.argv[1]
with open(os.path.join(d, "k5m.csv"), "rb") as f, open(os.path.join(d, "k5m_bad.csv"), "wb") as g:
    for i, line in enumerate(f):
        if i == 3000000:
            c = line.split(b","); c[3] = b"-1"; line = b",".join(c)
        g.write(line)
EOF
fi

# --- runs ----------------------------------------------------------------------------
n=0
bad=0
run() { # name threads binary args...
  local name=$1 t=$2 bin=$3; shift 3
  local o=$work/out/$name.$t.$(basename "$bin")
  rm -f "$o.file"
  local src=${stdin_from:-/dev/null}
  if [ "$t" = d ]; then
    "$bin" "$@" < "$src" > "$o.stdout" 2> "$o.stderr"; echo $? > "$o.rc"
  else
    RAYON_NUM_THREADS=$t "$bin" "$@" < "$src" > "$o.stdout" 2> "$o.stderr"; echo $? > "$o.rc"
  fi
}
case_() { # name args... (a literal OUT is replaced by an --output path)
  local name=$1; shift
  for t in 1 d; do
    local a=() x
    for x in "$@"; do
      if [ "$x" = OUT ]; then a+=(--output "$work/out/$name.$t.file"); else a+=("$x"); fi
    done
    for bin in "$old" "$new"; do
      # With REUSE=1, the outputs of an earlier run in WORKDIR are kept.
      if [ "${REUSE:-0}" = 1 ] && [ -f "$work/out/$name.$t.$(basename "$bin").rc" ]; then
        continue
      fi
      # An existing target must stay as it is on error.
      [ -n "$(printf '%s\n' "$@" | grep -x OUT)" ] && echo previous > "$work/out/$name.$t.file"
      run "$name" $t "$bin" "${a[@]}"
      local o=$work/out/$name.$t.$(basename "$bin")
      if [ -f "$work/out/$name.$t.file" ]; then mv "$work/out/$name.$t.file" "$o.file"; else rm -f "$o.file"; fi
    done
    local po=$work/out/$name.$t.$(basename "$old") pn=$work/out/$name.$t.$(basename "$new")
    n=$((n + 1))
    local d=""
    for s in stdout stderr rc; do cmp -s "$po.$s" "$pn.$s" || d="$d $s"; done
    if [ -f "$po.file" ] || [ -f "$pn.file" ]; then cmp -s "$po.file" "$pn.file" 2>/dev/null || d="$d file"; fi
    if [ -n "$d" ]; then
      bad=$((bad + 1)); echo "DIFFERS: $name threads=$t:$d"
    elif [ "${KEEP:-0}" != 1 ]; then
      rm -f "$pn.stdout" "$pn.stderr" "$pn.rc" "$pn.file"
    fi
  done
}
[ "$(basename "$old")" = "$(basename "$new")" ] && { echo "give the binaries different names"; exit 2; }

# Every input through k and forward (stdout and --output); the good ones through more
# models.
for f in "$in"/*.csv; do
  b=$(basename "$f" .csv)
  case $b in k5m*|f1m*) continue ;; esac
  case_ "k_stick_$b" k --model stick --input "$f"
  case_ "k_stick_out_$b" k --model stick --input "$f" OUT
  case_ "fwd_stick_$b" forward --model stick --input "$f"
  case $b in meas|sim100k|default|md_ristow|quoted_newlines|crlf|bom)
    case_ "k_stickslip_$b" k --model stickslip --input "$f" OUT
    case_ "fwd_stick_out_$b" forward --model stick --input "$f" OUT ;;
  esac
  case $b in default|md_ristow)
    case_ "k_auto_$b" k --model auto --input "$f" OUT
    case_ "fwd_contact_$b" forward --model contact --input "$f" OUT ;;
  esac
done
case_ k_default k --model stick
case_ fwd_default forward --model stick
stdin_from=$in/sim100k.csv case_ k_stdin_sim k --model stick --input -
stdin_from=$in/quoted_newlines.csv case_ fwd_stdin_q forward --model slip --input -
stdin_from=$in/crlf.csv case_ k_stdin_crlf k --model stick --input -
stdin_from=$in/unterminated.csv case_ k_stdin_unterminated k --model stick --input - OUT
case_ k_plot k --model stick --input "$in/sim100k.csv" --plot "$work/out/plot.svg"
if [ $big = 1 ]; then
  case_ k5m_stick k --model stick --input "$in/k5m.csv" OUT
  case_ k5m_stick_bad_stdout k --model stick --input "$in/k5m_bad.csv"
  case_ f1m_stick forward --model stick --input "$in/f1m.csv" OUT
fi
echo "$n cases, $bad differ"
echo "outputs kept in $work/out: $(du -sh "$work/out" | cut -f1) (remove the directory when done)"
[ $bad = 0 ]

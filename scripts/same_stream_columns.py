#!/usr/bin/env python3
"""Which cells of the differing cases of scripts/same_stream.sh changed, and by how much.

Usage: scripts/same_stream.sh OLD NEW WORKDIR > LOG; KEEP=1 is needed, so that both
binaries' outputs stay in WORKDIR/out. Then:

    python3 scripts/same_stream_columns.py LOG WORKDIR OLD_NAME NEW_NAME

OLD_NAME and NEW_NAME are the binaries' file names (what same_stream.sh puts in the output
names). For every case LOG lists as differing in stdout or file, the two CSVs are read row by
row; for each column it prints the cells that changed and the largest relative change
|a − b| / max(|a|, |b|) of the numeric ones, the spread of the changes of the `iterations`
column, and every text cell that changed (none should). A differing stderr or exit code is
reported as such: those are not cell changes.
"""
import collections
import csv
import sys


def main():
    if len(sys.argv) != 5:
        sys.exit(__doc__)
    log, work, old, new = sys.argv[1:]
    cases = []
    for line in open(log):
        if not line.startswith("DIFFERS: "):
            continue
        head, parts = line[len("DIFFERS: "):].rstrip("\n").split(": ")
        name, threads = head.split(" threads=")
        cases.append((f"{name}.{threads}", parts.split()))
    rel = collections.defaultdict(float)
    changed = collections.Counter()
    iters = collections.Counter()
    text = collections.Counter()
    rows = 0
    for case, parts in cases:
        for part in parts:
            if part not in ("stdout", "file"):
                print(f"{case}: {part} differs")
                continue
            a = list(csv.reader(open(f"{work}/out/{case}.{old}.{part}", newline="")))
            b = list(csv.reader(open(f"{work}/out/{case}.{new}.{part}", newline="")))
            if len(a) != len(b) or a[:1] != b[:1]:
                print(f"{case} {part}: rows or header differ ({len(a)} against {len(b)} records)")
                continue
            for x, y in zip(a[1:], b[1:]):
                rows += 1
                if x == y:
                    continue
                if len(x) != len(y):
                    print(f"{case} {part}: a row's width differs")
                    continue
                for h, u, v in zip(a[0], x, y):
                    if u == v:
                        continue
                    changed[h] += 1
                    try:
                        fu, fv = float(u), float(v)
                    except ValueError:
                        text[(h, u[:60], v[:60])] += 1
                        continue
                    if h == "iterations":
                        iters[int(fv - fu)] += 1
                    else:
                        rel[h] = max(rel[h], abs(fu - fv) / max(abs(fu), abs(fv)))
    print(f"{len(cases)} differing cases, {rows} rows compared")
    for h, n in changed.most_common():
        r = f"largest relative change {rel[h]:.2e}" if h in rel else ""
        print(f"{h:18s} {n:9d} cells changed  {r}")
    if iters:
        print("iterations, new − old: " + ", ".join(f"{d:+d} in {n}" for d, n in sorted(iters.items())))
    print(f"text cells changed: {sum(text.values())}")
    for (h, u, v), n in text.most_common(10):
        print(f"  {h}: {u!r} -> {v!r} ({n})")


if __name__ == "__main__":
    main()

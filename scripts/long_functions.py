#!/usr/bin/env python3
"""Functions longer than a number of lines in the Rust sources.

Counts the lines of each function from its `fn` line to its closing brace (bodies of test
modules included; declarations without a body are not counted) and lists those longer than a
threshold, longest first, as `lines file start-line name`.

    scripts/long_functions.py                  # list the functions over 150 lines under src/
                                               # and crates/ (the command line)
    scripts/long_functions.py --max 150        # ... and exit 1 if one is not exempt
    scripts/long_functions.py --min 100 src/fit

One function is exempt from --max: `iterate` in src/inverse/lm.rs, the Levenberg-Marquardt
iteration written to follow MINPACK's lmder step for step. It is listed, marked exempt.

Needs only python3.
"""
import argparse
import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# (path relative to the repository root, function name) allowed over the limit.
EXEMPT = {(os.path.join("src", "inverse", "lm.rs"), "iterate")}

FN = re.compile(r"\s*(pub(\([^)]*\))?\s+)?(const\s+)?(async\s+)?(unsafe\s+)?fn\s+(\w+)")


def functions(path):
    """(lines, start line, name) for every function with a body in the file at `path`."""
    lines = open(path, encoding="utf-8").read().split("\n")
    out = []
    for i, line in enumerate(lines):
        m = FN.match(line)
        if not m:
            continue
        j, depth, started = i, 0, False
        while j < len(lines):
            s = re.sub(r'"(\\.|[^"\\])*"', '""', lines[j])
            s = re.sub(r"'(\\.|[^'\\])'", "''", s)
            s = s.split("//")[0]
            for ch in s:
                if ch == "{":
                    depth += 1
                    started = True
                elif ch == "}":
                    depth -= 1
            if started and depth == 0:
                break
            if not started and s.rstrip().endswith(";"):
                break
            j += 1
        if started:
            out.append((j - i + 1, i + 1, m.group(6)))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument(
        "dirs",
        nargs="*",
        default=["src", "crates"],
        help="directories to scan (default: the library's src and the crates of crates/)",
    )
    ap.add_argument("--min", type=int, default=150, help="list functions longer than this")
    ap.add_argument(
        "--max", type=int, help="exit 1 if a function not exempt is longer than this many lines"
    )
    args = ap.parse_args()
    limit = args.max if args.max is not None else args.min
    found = []
    for d in args.dirs:
        top = d if os.path.isabs(d) else os.path.join(ROOT, d)
        for root, _, files in os.walk(top):
            for f in sorted(files):
                if not f.endswith(".rs"):
                    continue
                p = os.path.join(root, f)
                rel = os.path.relpath(p, ROOT)
                for n, start, name in functions(p):
                    if n > limit:
                        found.append((n, rel, start, name))
    over = 0
    for n, rel, start, name in sorted(found, reverse=True):
        exempt = (rel, name) in EXEMPT
        print(n, rel, start, name, *(["(exempt)"] if exempt else []))
        if not exempt:
            over += 1
    if args.max is not None and over:
        print(f"{over} function(s) over {args.max} lines", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())

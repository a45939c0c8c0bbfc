#!/usr/bin/env python3
"""The library's public surface: every item rustdoc lists for the crate `fitbead`.

Counts what a user of the library can name: structs, enums, unions, traits, functions, type
aliases, constants, statics and macros reachable from the crate root, each once (as rustdoc's
`all.html` lists them; methods and fields belong to their type and are not counted). The
command-line binary is not part of the library and is not counted. The count is that of the
default features; the non-default feature `bench-internals` (internals for the benchmarks, not
part of the API) adds the names its one module `src/bench_internals.rs` makes public, printed
apart and not counted.

    scripts/public_items.py                  # build the docs, print the list and the count
    scripts/public_items.py --max 150        # ... and exit 1 if the count is above 150
    scripts/public_items.py --no-build       # read an existing target/doc/fitbead/all.html

Needs only python3 and cargo.
"""
import argparse
import html
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def items(all_html):
    """(kind, path) for every item of rustdoc's all-items page."""
    out = []
    for kind, body in re.findall(
        r'<h3 id="(\w+)">.*?</h3>\s*<ul class="all-items">(.*?)</ul>', all_html, re.S
    ):
        for name in re.findall(r'<li><a href="[^"]+">([^<]+)</a></li>', body):
            out.append((kind, html.unescape(name)))
    return out


def feature_items():
    """The names the feature `bench-internals` adds: every name `src/bench_internals.rs` makes
    public (`pub use` lists, renamed with `as`, and its own `pub` items)."""
    path = os.path.join(ROOT, "src", "bench_internals.rs")
    if not os.path.exists(path):
        return []
    with open(path, encoding="utf-8") as f:
        text = re.sub(r"//[^\n]*", "", f.read())
    names = []
    for body in re.findall(r"\bpub use ([^;]+);", text):
        body = re.sub(r"\s+", " ", body)
        m = re.match(r"(.*?)::\{(.*)\}$", body.strip())
        parts = [p.strip() for p in m.group(2).split(",")] if m else [body.rsplit("::", 1)[-1]]
        for p in filter(None, parts):
            names.append(p.split(" as ")[-1].strip())
    names += re.findall(
        r"^pub (?:fn|struct|enum|trait|type|const|static|union) (\w+)", text, re.M
    )
    return names


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--max", type=int, help="exit 1 when more items than this are public")
    ap.add_argument("--no-build", action="store_true", help="do not run cargo doc first")
    ap.add_argument("--quiet", action="store_true", help="print the counts only")
    args = ap.parse_args()
    target = os.environ.get("CARGO_TARGET_DIR", os.path.join(ROOT, "target"))
    page = os.path.join(target, "doc", "fitbead", "all.html")
    if not args.no_build:
        subprocess.run(
            ["cargo", "doc", "--no-deps", "--lib", "-p", "fitbead", "--quiet"],
            cwd=ROOT,
            check=True,
        )
    with open(page, encoding="utf-8") as f:
        found = items(f.read())
    if not found:
        sys.exit(f"{page}: no items found (has rustdoc's page layout changed?)")
    by_kind = {}
    for kind, name in found:
        by_kind.setdefault(kind, []).append(name)
    if not args.quiet:
        for kind in sorted(by_kind):
            for name in by_kind[kind]:
                print(f"{kind:10} {name}")
    summary = ", ".join(f"{len(v)} {k}" for k, v in sorted(by_kind.items()))
    print(f"public items of fitbead: {len(found)} ({summary})")
    extra = feature_items()
    if extra:
        print(
            f"not counted: the feature bench-internals (not part of the API) adds {len(extra)}: "
            + ", ".join(f"bench_internals::{n}" for n in extra)
        )
    if args.max is not None and len(found) > args.max:
        print(f"more than {args.max} public items", file=sys.stderr)
        sys.exit(1)


if __name__ == "__main__":
    main()

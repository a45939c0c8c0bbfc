#!/usr/bin/env python3
"""The dependencies whose features resolve differently in the test build (`cargo test
--release` at the root: the library, the command line and the tests' dev-dependencies) and in
the Python wheel's build (`-p fitbead-python`). Each such crate, and every crate built on it,
is compiled twice by scripts/test.sh, once for each build; python/Cargo.toml and
crates/fitbead-cli/Cargo.toml declare the features that keep the two alike.

Usage: python3 scripts/wheel_features.py [--strict]

Prints one line per differing crate (the library itself excepted: the binding builds it
without the figures' features) and exits 0; with --strict, exits 1 when any differs. Runs
`cargo tree` twice.
"""
import subprocess
import sys


def features(args):
    out = subprocess.run(
        ["cargo", "tree", *args, "-f", "{p} [{f}]", "--prefix", "none", "--no-dedupe"],
        check=True, capture_output=True, text=True,
    ).stdout
    found = {}
    for line in out.splitlines():
        if " [" not in line:
            continue
        name = line.split(" [")[0].replace(" (*)", "")
        feats = line[line.index("[") + 1:line.rindex("]")]
        found.setdefault(name, set()).update(f for f in feats.split(",") if f)
    return found


def main():
    strict = "--strict" in sys.argv[1:]
    tests = features(["-e", "normal,build,dev"])
    wheel = features(["-p", "fitbead-python", "-e", "normal,build"])
    differ = [
        (k, sorted(tests[k] - wheel[k]), sorted(wheel[k] - tests[k]))
        for k in sorted(set(tests) & set(wheel))
        if tests[k] != wheel[k] and not k.startswith("fitbead v")
    ]
    for name, only_tests, only_wheel in differ:
        print(f"wheel_features: {name}: only in the test build {only_tests}, only in the wheel's {only_wheel}")
    if not differ:
        print("wheel_features: the wheel's build shares every dependency's features with the test build")
    return 1 if strict and differ else 0


if __name__ == "__main__":
    sys.exit(main())

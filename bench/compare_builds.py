"""Two builds of the Google Benchmark executable, before and after a change, in one run.

    python3 bench/compare_builds.py OLD_BENCH NEW_BENCH [--rounds 5] [--filter REGEX] [--min-time 0.1]

Runs the two executables alternately, ``--rounds`` times each with the same
filter (so that the drifts of a shared machine fall on both), keeps the
median items/s of every benchmark both have, and prints a Markdown table of
old, new and new/old. Benchmarks only one build has are listed after it.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import tempfile


def run_once(executable: str, pattern: str, min_time: float) -> dict:
    with tempfile.NamedTemporaryFile(suffix=".json") as out:
        subprocess.run([executable, f"--benchmark_filter={pattern}", f"--benchmark_min_time={min_time}",
                        f"--benchmark_out={out.name}", "--benchmark_out_format=json"],
                       check=True, stdout=subprocess.DEVNULL)
        with open(out.name) as f:
            report = json.load(f)
    return {b["name"]: b["items_per_second"] for b in report["benchmarks"] if "items_per_second" in b}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("old")
    parser.add_argument("new")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--filter", default=".")
    parser.add_argument("--min-time", type=float, default=0.1)
    args = parser.parse_args()

    samples = {"old": {}, "new": {}}
    for _ in range(args.rounds):
        for which in ("old", "new"):
            for name, rate in run_once(getattr(args, which), args.filter, args.min_time).items():
                samples[which].setdefault(name, []).append(rate)
    old = {name: statistics.median(rates) for name, rates in samples["old"].items()}
    new = {name: statistics.median(rates) for name, rates in samples["new"].items()}
    print(f"medians of {args.rounds} alternating runs, M items/s\n")
    print("| benchmark | old | new | new/old |\n|---|---:|---:|---:|")
    for name in (n for n in new if n in old):
        print(f"| {name} | {old[name] / 1e6:.1f} | {new[name] / 1e6:.1f} | {new[name] / old[name]:.3f} |")
    only = [n for n in new if n not in old] + [n for n in old if n not in new]
    for name in only:
        side = "new" if name in new else "old"
        print(f"| {name} ({side} only) | | {(new if side == 'new' else old)[name] / 1e6:.1f} | |")


if __name__ == "__main__":
    main()

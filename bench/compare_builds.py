"""Two builds of the Google Benchmark executable, before and after a change, in one run.

    python3 bench/compare_builds.py OLD_BENCH NEW_BENCH [--rounds 5] [--filter REGEX] [--min-time 0.1]
                                    [--repetitions 1] [--compensated]

Runs the two executables alternately, ``--rounds`` times each with the same
filter (so that the drifts of a shared machine fall on both), keeps the
median items/s of every benchmark both have, and prints a Markdown table of
old, new and new/old. Benchmarks only one build has are listed after it.
With ``--repetitions N`` each run repeats every benchmark N times in a random
interleaved order (Google Benchmark's random interleaving), so that the
benchmarks of one run share its drifts too; the medians are then over all
repetitions of all rounds. ``--compensated`` adds each build's ratios of the
energy-compensated benchmarks to their plain twins (``eval_compensated`` to
``eval``, ``eval_material_compensated`` to ``eval_material``). Pin it to one
core with ``taskset -c 1`` (the runs inherit the affinity).
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import tempfile


def run_once(executable: str, pattern: str, min_time: float, repetitions: int) -> dict:
    """{benchmark: [items/s of each repetition]}"""
    interleaved = [f"--benchmark_repetitions={repetitions}", "--benchmark_enable_random_interleaving=true"]
    with tempfile.NamedTemporaryFile(suffix=".json") as out:
        subprocess.run([executable, f"--benchmark_filter={pattern}", f"--benchmark_min_time={min_time}",
                        f"--benchmark_out={out.name}", "--benchmark_out_format=json"]
                       + (interleaved if repetitions > 1 else []),
                       check=True, stdout=subprocess.DEVNULL)
        with open(out.name) as f:
            report = json.load(f)
    rates: dict = {}
    for b in report["benchmarks"]:
        if b.get("run_type", "iteration") == "iteration" and "items_per_second" in b:
            rates.setdefault(b.get("run_name", b["name"]), []).append(b["items_per_second"])
    return rates


def plain_twin(name: str) -> str:
    return name.replace("eval_material_compensated/", "eval_material/").replace("eval_compensated/", "eval/")


def print_compensated_ratios(which: str, medians: dict) -> None:
    print(f"\n{which}: with the energy compensation / without, M items/s\n")
    print("| benchmark | compensated | plain | ratio |\n|---|---:|---:|---:|")
    for name, rate in medians.items():
        if "compensated/" in name and plain_twin(name) in medians:
            plain = medians[plain_twin(name)]
            print(f"| {name} | {rate / 1e6:.1f} | {plain / 1e6:.1f} | {rate / plain:.3f} |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("old")
    parser.add_argument("new")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--filter", default=".")
    parser.add_argument("--min-time", type=float, default=0.1)
    parser.add_argument("--repetitions", type=int, default=1)
    parser.add_argument("--compensated", action="store_true")
    args = parser.parse_args()

    samples = {"old": {}, "new": {}}
    for _ in range(args.rounds):
        for which in ("old", "new"):
            for name, rates in run_once(getattr(args, which), args.filter, args.min_time, args.repetitions).items():
                samples[which].setdefault(name, []).extend(rates)
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
    if args.compensated:
        print_compensated_ratios("old", old)
        print_compensated_ratios("new", new)


if __name__ == "__main__":
    main()

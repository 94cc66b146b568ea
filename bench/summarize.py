"""Summarize a Google Benchmark JSON of principled_brdf_bench: items/s per
benchmark, then the ratios that the performance targets are stated in.

    python bench/summarize.py bench/results.json
"""

from __future__ import annotations

import json
import sys


def load(path: str) -> dict:
    """{benchmark name without the aggregate suffix: items per second (median)}"""
    with open(path) as f:
        report = json.load(f)
    rates = {}
    for entry in report["benchmarks"]:
        if entry.get("run_type") == "aggregate" and entry.get("aggregate_name") != "median":
            continue
        name = entry.get("run_name", entry["name"])
        rates[name] = entry["items_per_second"]
    return rates, report.get("context", {})


def find(rates: dict, prefix: str) -> float | None:
    matches = [rate for name, rate in rates.items() if name.startswith(prefix)]
    return matches[0] if matches else None


def main(path: str) -> None:
    rates, context = load(path)
    threads = context.get("num_cpus", 2)
    isas = [isa for isa in ("avx512", "avx2", "sse2", "neon") if find(rates, f"eval/{isa}/")]
    best = isas[0]
    print(f"machine: {threads} CPUs at {context.get('mhz_per_cpu', '?')} MHz, {context.get('date', '')}\n")
    print("| benchmark | M items/s |")
    print("|---|---:|")
    for name, rate in sorted(rates.items()):
        print(f"| `{name}` | {rate / 1e6:.1f} |")

    def ratio(a, b):
        return f"{a / b:.2f}x" if a and b else "n/a"

    small, large = 4096, 16 << 20
    in_cache = {layout: find(rates, f"eval/{best}/{layout}/uniform/{small}/1/") for layout in ("aos", "soa")}
    native = {layout: find(rates, f"native_loop/{layout}/{small}/1") for layout in ("aos", "soa")}
    native_best = max(v for v in native.values() if v)
    reference = find(rates, f"reference_f64/{small}/1")
    big_all = find(rates, f"eval/{best}/aos/uniform/{large}/{threads}/")
    copy_all = find(rates, f"copy/{large}/{threads}/")
    print(f"\n| target ({best}) | measured |")
    print("|---|---:|")
    print(f"| in cache, 1 thread, uniform, (N,3): vs float64 reference (>= 10x) | {ratio(in_cache['aos'], reference)} |")
    print(f"| in cache, 1 thread, uniform, (3,N): vs float64 reference | {ratio(in_cache['soa'], reference)} |")
    print(f"| in cache, (N,3) vs the -march=native -ffast-math loop, (N,3) (>= 1.0x) | {ratio(in_cache['aos'], native['aos'])} |")
    print(f"| in cache, (3,N) vs the -march=native -ffast-math loop, (3,N) (>= 1.0x) | {ratio(in_cache['soa'], native['soa'])} |")
    print(f"| in cache, best layout vs the compiler's best layout | {ratio(max(in_cache.values()), native_best)} |")
    print(f"| 16M pairs, all threads, (N,3), vs the copy kernel (>= 0.85x) | {ratio(big_all, copy_all)} |")
    copy_streaming = find(rates, f"copy_streaming/{large}/{threads}/")
    if copy_streaming:  # the copy with eval's non-temporal stores for a call past the caches
        print(f"| same, vs the copy by non-temporal stores | {ratio(big_all, copy_streaming)} |")
    for size, threads_used in ((small, 1), (65536, 1), (large, threads)):
        for material in ("uniform", "per_element"):
            aos = find(rates, f"eval/{best}/aos/{material}/{size}/{threads_used}/")
            soa = find(rates, f"eval/{best}/soa/{material}/{size}/{threads_used}/")
            print(f"| (N,3) vs (3,N), N={size}, {threads_used} thread(s), {material} (>= 0.9x) | {ratio(aos, soa)} |")
    for material in ("uniform", "per_element"):
        for isa in isas:
            sample = find(rates, f"sample/{isa}/aos/{material}/{small}/1/")
            evaluate = find(rates, f"eval/{isa}/aos/{material}/{small}/1/")
            if sample:
                print(f"| {isa} sampling vs eval, in cache, {material} (>= 0.5x) | {ratio(sample, evaluate)} |")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "bench/results.json")

"""pb.eval and pb.sample beside Mitsuba 3's `principled` BSDF on the same pairs and material.

    apt-get install libllvm19                     # Debian 12's LLVM 19, for Dr.Jit's LLVM backend
    pip install mitsuba==3.9.1 drjit==1.5.0
    DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM-19.so python3 bench/compare_mitsuba.py

Dr.Jit 1.5 emits `llvm.maximum` (fmaximum), which LLVM 16 and older cannot
select for x86: the process aborts inside LLVM, so the script refuses an older
LLVM. Without DRJIT_LIBLLVM_PATH Dr.Jit picks whichever libLLVM it finds first.

Mitsuba runs its LLVM backend (variant llvm_ad_rgb, no gradients asked for),
which compiles for the host CPU whatever instruction set this library is
forced to (PRINCIPLED_BRDF_ISA). Mitsuba traces its kernel for the material:
a lobe whose parameter is zero (sheen, clearcoat, spec_trans, ...) is left out,
and the uniform parameters enter as scalar kernel inputs. Its `wi`
is this library's `wo` (towards the viewer) and its `eval` includes the
cosine, so it is timed against `pb.eval(..., cosine=True)`; its `sample`
against `pb.sample` with given uniforms. Each figure is the best of
`--repeats` timed runs (and of at least 0.2 s of runs) after a warm-up (which
compiles Mitsuba's kernel) and a pause that lets the other library's threads sleep;
Dr.Jit runs asynchronously, so its timer stops after `dr.sync_thread()`.
"One core" pins the process to CPU 0 (sched_setaffinity) and runs both on
one thread; "all" uses every core. `--material` takes a preset instead of
the benchmark material. `--model disney2015` compares the 2015 BSDF (Mitsuba's
`principled` with `spec_trans`, `--spec-trans`, default 1) on pairs over the
whole sphere. Prints a Markdown table (M pairs/s and ratios) headed by the CPU
and this library's instruction set, then the agreement of the two evals on
the timed pairs (reported, never enforced: Mitsuba's BSDF is not the 2014
model, and its sheen, clearcoat and flatness are not the 2015 model's); not a
test dependency.
"""

from __future__ import annotations

import argparse
import os
import platform
import time

import numpy as np

import principled_brdf as pb

MATERIAL = dict(base_color=(0.82, 0.67, 0.16), metallic=0.2, roughness=0.4, sheen=0.2, clearcoat=0.5,
                clearcoat_gloss=0.7, specular=0.5)
# this library's names for Mitsuba's `principled` parameters (it has no subsurface)
MITSUBA_NAMES = {"metallic": "metallic", "specular": "specular", "specular_tint": "spec_tint", "roughness": "roughness",
                 "anisotropic": "anisotropic", "sheen": "sheen", "sheen_tint": "sheen_tint", "clearcoat": "clearcoat",
                 "clearcoat_gloss": "clearcoat_gloss", "spec_trans": "spec_trans", "flatness": "flatness"}


def material_named(name: str) -> pb.Material:
    """`--material`: the default benchmark material, or a preset (every parameter passed to both)."""
    return pb.Material(**MATERIAL) if name == "benchmark" else pb.presets.get(name)


def best_seconds(run, repeats: int, min_seconds: float = 0.2) -> float:
    """The fastest of at least `repeats` runs and `min_seconds` of runs, after a
    warm-up (page faults, Mitsuba's JIT) and a pause: either library's worker
    threads spin for a while after a call before they sleep, and would take the
    other's second core."""
    run()
    time.sleep(0.05)
    best, total, count = np.inf, 0.0, 0
    while count < repeats or total < min_seconds:
        start = time.perf_counter()
        run()
        elapsed = time.perf_counter() - start
        best, total, count = min(best, elapsed), total + elapsed, count + 1
    return best


def cpu_name() -> str:
    """The CPU's vendor and model as /proc/cpuinfo names them."""
    fields: dict[str, str] = {}
    try:
        with open("/proc/cpuinfo") as lines:
            for line in lines:
                key, _, value = line.partition(":")
                fields.setdefault(key.strip(), value.strip())
    except OSError:
        pass
    vendor = fields.get("vendor_id", fields.get("CPU implementer", "unknown vendor"))
    return f"{vendor} {fields.get('model name', platform.processor() or 'unknown model')}"


def random_pairs(n: int, seed: int = 1, sphere: bool = False):
    """wi, wo over the upper hemisphere (or the whole sphere) and the uniforms."""
    rng = np.random.default_rng(seed)

    def directions(size):
        v = rng.normal(size=(size, 3))
        if not sphere:
            v[:, 2] = np.abs(v[:, 2]) + 1e-3
        return (v / np.linalg.norm(v, axis=1, keepdims=True)).astype(np.float32)

    return directions(n), directions(n), rng.random((n, 3), dtype=np.float32)


def mitsuba_timers(material: pb.Material, n: int, wi, wo, u, repeats: int):
    """Best seconds of Mitsuba's eval and sample, and its eval's values as (n, 3)."""
    import drjit as dr
    import mitsuba as mi

    mi.set_variant("llvm_ad_rgb")
    values = material.as_dict()
    if float(values["subsurface"]) != 0.0:
        raise SystemExit("Mitsuba's principled BSDF has no subsurface: choose a material without it")
    bsdf = mi.load_dict({"type": "principled",
                         "base_color": {"type": "rgb", "value": [float(c) for c in values["base_color"]]},
                         **{theirs: float(values[ours]) for ours, theirs in MITSUBA_NAMES.items()}})
    ctx = mi.BSDFContext()
    si = dr.zeros(mi.SurfaceInteraction3f, n)
    si.wi = mi.Vector3f(wo[:, 0], wo[:, 1], wo[:, 2])  # Mitsuba's wi: towards the viewer
    light = mi.Vector3f(wi[:, 0], wi[:, 1], wi[:, 2])
    sample1, sample2 = mi.Float(u[:, 0]), mi.Point2f(u[:, 1], u[:, 2])

    def evaluate():
        value = bsdf.eval(ctx, si, light)
        dr.eval(value)
        dr.sync_thread()
        return value

    def sample():
        drawn, weight = bsdf.sample(ctx, si, sample1, sample2)
        dr.eval(drawn.wo, drawn.pdf, weight)
        dr.sync_thread()

    seconds = {"eval": best_seconds(evaluate, repeats), "sample": best_seconds(sample, repeats)}
    # Dr.Jit hands a Color3f to numpy as (3, n): one row per channel
    return seconds, evaluate().numpy().T


def agreement(theirs: np.ndarray, ours: np.ndarray) -> str:
    """|Mitsuba - pb| / |pb| over the values finite and nonzero in both: its max
    and median, and its max over the values at least 1e-3 of the largest (the
    far tails of transmission are float32 rounding in both)."""
    theirs, ours = theirs.astype(np.float64), ours.astype(np.float64)
    both = np.isfinite(theirs) & np.isfinite(ours) & (theirs != 0) & (ours != 0)
    if not both.any():
        return "no value finite and nonzero in both"
    relative = np.abs(theirs[both] - ours[both]) / np.abs(ours[both])
    large = np.abs(ours[both]) >= 1e-3 * np.abs(ours[both]).max()
    return (f"max relative difference {relative.max():.2g} (median {np.median(relative):.2g}) over {both.sum():,} "
            f"of {theirs.size:,} values; {relative[large].max():.2g} over the {large.sum():,} at least 1e-3 of the largest")


def library_timers(m: pb.Material, n: int, wi, wo, u, threads, repeats: int, model: str):
    out = np.empty_like(wi)
    options = dict(threads=threads, model=model)
    return {
        "eval, out=, check=False": best_seconds(lambda: pb.eval(m, wi, wo, cosine=True, out=out, check=False,
                                                                **options), repeats),
        "eval, out= (checked)": best_seconds(lambda: pb.eval(m, wi, wo, cosine=True, out=out, **options), repeats),
        "eval, fresh output (checked)": best_seconds(lambda: pb.eval(m, wi, wo, cosine=True, **options), repeats),
        "sample, u given": best_seconds(lambda: pb.sample(m, wo, u=u, **options), repeats),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[1 << 16, 1 << 20, 1 << 24])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--material", default="benchmark", choices=["benchmark", *pb.presets.names()],
                        help="the benchmark material (every lobe but subsurface on) or a preset")
    parser.add_argument("--model", default="disney2014", choices=["disney2014", "disney2015"])
    parser.add_argument("--spec-trans", type=float, default=1.0, help="the material's spec_trans with disney2015")
    args = parser.parse_args()
    import drjit as dr
    import mitsuba as mi

    llvm = dr.detail.llvm_version()
    if llvm is None or llvm[0] < 17:
        raise SystemExit(f"Dr.Jit found LLVM {llvm}, which aborts on Dr.Jit 1.5's fmaximum (checked with 19): "
                         "set DRJIT_LIBLLVM_PATH to libLLVM-19.so")

    material = material_named(args.material)
    sphere = args.model == "disney2015"
    if sphere:
        material = material.replace(spec_trans=args.spec_trans)

    cores = sorted(os.sched_getaffinity(0))
    print(f"{cpu_name()}; principled-brdf {pb.__version__}, ISA {pb.cpu_info()['isa']}; Mitsuba {mi.__version__} "
          f"llvm_ad_rgb (Dr.Jit {dr.__version__}, LLVM {'.'.join(map(str, llvm))}); material {args.material}; "
          f"model {args.model}" + (f", spec_trans {args.spec_trans:g}, pairs over the sphere" if sphere else "") + "\n")
    print("| pairs | cores | call | pb M pairs/s | Mitsuba M pairs/s | pb / Mitsuba |\n|---:|---|---|---:|---:|---:|")
    agreements = {}
    for label, affinity, threads in (("one (pinned)", {cores[0]}, 1), ("all", set(cores), None)):
        os.sched_setaffinity(0, affinity)
        # Dr.Jit counts the calling thread as one of its threads: 1 means no worker
        dr.set_thread_count(len(affinity))
        for n in args.sizes:
            wi, wo, u = random_pairs(n, sphere=sphere)
            theirs, mitsuba_values = mitsuba_timers(material, n, wi, wo, u, args.repeats)
            ours = library_timers(material, n, wi, wo, u, threads, args.repeats, args.model)
            if n not in agreements:
                agreements[n] = agreement(mitsuba_values, pb.eval(material, wi, wo, cosine=True, model=args.model))
            del mitsuba_values
            for call, seconds in ours.items():
                peer = theirs["sample" if call.startswith("sample") else "eval"]
                print(f"| {n:,} | {label} | {call} | {n / seconds / 1e6:.0f} | {n / peer / 1e6:.0f} | "
                      f"{peer / seconds:.2f}x |", flush=True)
    os.sched_setaffinity(0, set(cores))
    print("\nMitsuba's eval against pb.eval(..., cosine=True) on the timed pairs:")
    for n, text in agreements.items():
        print(f"- {n:,} pairs: {text}")


if __name__ == "__main__":
    main()

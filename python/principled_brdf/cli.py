"""``python -m principled_brdf``: demo, render, bench, info.

Every subcommand has ``--help``; bad arguments print a one-line error and
exit with status 2. The numeric options are bounded so that a job fits in
memory and ends: ``--pairs`` at most 2^27, ``--repeats`` 1 to 100 with
pairs x repeats at most 2^31, ``--resolution`` 2 to 16384 (the demo's spheres
8 to 682: its 36 spheres x resolution² x 256 samples at most 2^32), ``--samples`` 1 to
65536 per pixel with resolution² x samples at most 2^34 (with an environment),
``--exposure`` finite, > 0 and at most 1e20, ``--light`` three finite numbers
not all 0, ``--light-intensity`` finite, >= 0 and at most 1e20, ``--param``
values inside their domains and what the kernels take (``roughness`` up to
1e4, the others up to 1e20), ``--environment`` a built-in name or an existing
``.exr``/``.hdr`` file, ``--tone`` one of the tone curves, ``--output`` a file
that can be made in an existing folder (checked before any work).
"""

from __future__ import annotations

import argparse
import contextlib
import platform
import sys
import time
from typing import TYPE_CHECKING

import numpy as np

from . import _models
from ._batch import FLOAT32_LIMITS
from .material import PARAMETERS, Material
from .environment import MAP_FORMATS
from .demo import (MAX_PICTURE_RESOLUTION, MAX_PICTURE_WORK, MIN_PICTURE_RESOLUTION, PICTURE_RESOLUTION,
                   PICTURE_SAMPLES, PICTURE_SPHERES)
from .render import ENVIRONMENT_NAMES, MAX_RESOLUTION, MAX_SAMPLE_WORK, MAX_SAMPLES

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator, Sequence

    from .measured import MerlBRDF

# Each pair holds about 100 bytes across the benchmarks' arrays: 2**27 pairs is 13 GB.
MAX_PAIRS = 1 << 27
# Timed runs: each one evaluates every pair (the benchmark's numpy model at ~10 M pairs/s on two cores).
MAX_REPEATS = 100
MAX_PAIR_WORK = 1 << 31  # pairs x repeats
MAX_EXPOSURE = 1e20  # a linear picture times this stays inside float32 (its values are far below 1e18)


class _Progress:
    """Prints what is being done, with the time since the command started."""

    def __init__(self, quiet: bool = False) -> None:
        self.start = time.perf_counter()
        self.quiet = quiet

    def __call__(self, message: str) -> None:
        if not self.quiet:
            print(f"[{time.perf_counter() - self.start:6.1f}s] {message}" if message.endswith("...") else message,
                  flush=True)


def _positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {value}")
    return value


def _at_most(upper: int, what: str, lower: int = 1) -> Callable[[str], int]:
    """A positive integer option from ``lower`` to ``upper`` (beyond it the job cannot fit in memory or end)."""
    def parse(text: str) -> int:
        value = _positive_int(text)
        if value < lower:
            raise argparse.ArgumentTypeError(f"expected at least {lower} {what}, got {value}")
        if value > upper:
            raise argparse.ArgumentTypeError(f"expected at most {upper} {what}, got {value}")
        return value
    return parse


def _exposure(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not (np.isfinite(value) and 0.0 < value <= MAX_EXPOSURE):
        raise argparse.ArgumentTypeError(f"expected a finite number > 0 and at most {MAX_EXPOSURE:g}, got {text!r}")
    return value


def _intensity(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not (np.isfinite(value) and 0.0 <= value <= MAX_EXPOSURE):
        raise argparse.ArgumentTypeError(f"expected a finite number >= 0 and at most {MAX_EXPOSURE:g}, got {text!r}")
    return value


ENVIRONMENT_CHOICES = ENVIRONMENT_NAMES + ("none",)


def _environment(text: str) -> str:
    """A built-in environment's name, ``none``, or an existing ``.exr``/``.hdr`` map."""
    import os

    if text in ENVIRONMENT_CHOICES:
        return text
    if os.path.splitext(text)[1].lower() not in MAP_FORMATS:
        raise argparse.ArgumentTypeError(f"expected {', '.join(ENVIRONMENT_CHOICES)} or a "
                                         f"{'/'.join(MAP_FORMATS)} latitude-longitude map, got {text!r}")
    if not os.path.isfile(text):
        raise argparse.ArgumentTypeError(f"no such file: {text!r}")
    return text


def _vector(text: str) -> tuple[float, ...]:
    try:
        values = tuple(float(v) for v in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected three comma-separated numbers, got {text!r}") from None
    if len(values) != 3 or not np.all(np.isfinite(values)) or not any(values):
        raise argparse.ArgumentTypeError(f"expected three finite comma-separated numbers, not all 0, got {text!r}")
    return values


def _parameter(text: str) -> tuple[str, float | tuple[float, ...]]:
    name, sep, value = text.partition("=")
    if not sep or name not in PARAMETERS:
        raise argparse.ArgumentTypeError(
            f"expected NAME=VALUE with NAME one of {', '.join(PARAMETERS)}, got {text!r}")
    try:
        parsed = tuple(float(v) for v in value.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"{name}: expected a number (base_color: R,G,B), got {value!r}") from None
    info = PARAMETERS[name]
    if len(parsed) != info.slots:
        raise argparse.ArgumentTypeError(f"{name}: expected {info.slots} comma-separated number(s), got {value!r}")
    for number in parsed:
        if not info.lower <= number <= info.upper:  # NaN fails both
            raise argparse.ArgumentTypeError(f"{name}: {number!r} is outside its domain [{info.lower:g}, {info.upper:g}]")
        if number > FLOAT32_LIMITS.get(name, np.inf):
            raise argparse.ArgumentTypeError(f"{name}: {number!r} is beyond {FLOAT32_LIMITS[name]:g}, the most the "
                                             "kernels take")
    return name, parsed if info.slots == 3 else parsed[0]


def _image_path(formats: Sequence[str]) -> Callable[[str], str]:
    """An output path whose extension is one of ``formats`` (the error names the extension), in a
    folder where a file can be made (checked before any work, by making one there)."""
    def parse(text: str) -> str:
        import os

        extension = os.path.splitext(text)[1].lower()
        if extension not in formats:
            raise argparse.ArgumentTypeError(f"cannot write {extension or 'a file without an extension'!r} images; "
                                             f"supported: {', '.join(formats)}")
        problem = _unwritable(text)
        if problem is not None:
            raise argparse.ArgumentTypeError(f"cannot write {text!r}: {problem}")
        return text
    return parse


def _unwritable(path: str) -> str | None:
    """Why ``path`` cannot be written, or None: its folder must exist and take a new file (tried with
    a temporary one: permissions alone do not say, e.g. for root or on a read-only file system),
    and the path must not be a folder or a file that cannot be written."""
    import os
    import tempfile

    folder = os.path.dirname(path) or os.curdir
    if not os.path.isdir(folder):
        return f"no such folder {folder!r}"
    if os.path.isdir(path):
        return "it is a folder"
    if os.path.exists(path) and not os.access(path, os.W_OK):
        return "permission denied"
    try:
        with tempfile.NamedTemporaryFile(dir=folder, prefix=".principled_brdf_", suffix=".tmp"):
            pass
    except OSError as error:
        return f"a file cannot be made in {folder!r} ({error.strerror or error})"
    return None


def _timing_limits(args: argparse.Namespace) -> str | None:
    """What is wrong with demo's or bench's options together, or None."""
    if args.pairs * args.repeats > MAX_PAIR_WORK:
        return (f"argument --repeats: {args.repeats} runs of {args.pairs} pairs is beyond {MAX_PAIR_WORK} (2^31) pairs "
                f"in all; at most {max(MAX_PAIR_WORK // args.pairs, 1)} repeats of this many pairs")
    return None


def _demo_limits(args: argparse.Namespace) -> str | None:
    """What is wrong with demo's options together, or None: the timing's work and the picture's,
    spheres x pixels x samples at most MAX_PICTURE_WORK (render's limit, counting what its samples cost)."""
    work = PICTURE_SPHERES * args.resolution * args.resolution * PICTURE_SAMPLES
    if work > MAX_PICTURE_WORK:
        return (f"argument --resolution: {PICTURE_SPHERES} spheres of {args.resolution}x{args.resolution} pixels at "
                f"{PICTURE_SAMPLES} samples is {work} samples, beyond the picture's {MAX_PICTURE_WORK} (2^32); at "
                f"most {MAX_PICTURE_RESOLUTION} pixels per sphere")
    return _timing_limits(args)


def _render_limits(args: argparse.Namespace) -> str | None:
    """What is wrong with render's options together, or None."""
    pixels = args.resolution * args.resolution
    if args.environment != "none" and args.samples is not None and pixels * args.samples > MAX_SAMPLE_WORK:
        return (f"argument --samples: {args.samples} per pixel at {args.resolution}x{args.resolution} is "
                f"{pixels * args.samples} samples, beyond {MAX_SAMPLE_WORK} (2^34); at most "
                f"{max(MAX_SAMPLE_WORK // pixels, 1)} per pixel at this resolution")
    return None


@contextlib.contextmanager
def _naming_the_output(path: str) -> Iterator[None]:
    """An OSError inside (writing the output) as one naming ``--output``."""
    try:
        yield
    except OSError as error:
        raise OSError(f"argument --output: cannot write {path!r}: {error.strerror or error}") from None


def _demo(args: argparse.Namespace, report: Callable[[str], object]) -> None:
    from .demo import run

    with _naming_the_output(args.output):  # (the demo's one file is its picture)
        run(pairs=args.pairs, output=args.output, repeats=args.repeats, resolution=args.resolution, report=report)


def _render(args: argparse.Namespace, report: Callable[[str], object]) -> None:
    from . import presets
    from .render import render_sphere, save_image

    if args.merl is not None:
        if args.preset or args.param or args.energy_compensation or args.model != _models.DEFAULT_MODEL:
            raise ValueError("--merl: measured data is rendered as it is (no --preset, --param, --model or "
                             "--energy-compensation)")
        from .measured import load_merl

        material: Material | MerlBRDF = load_merl(args.merl)
        name = f"the MERL data {args.merl}"
    else:
        params = presets.parameters(args.preset) if args.preset else {}
        params.update(dict(args.param or []))
        material = Material(**params)
        name = str(material)
    environment = None if args.environment == "none" else args.environment
    lighting = "a key light" if environment is None else f"the {environment} environment"
    if environment is not None and args.samples is not None:
        lighting += f" ({args.samples} samples per pixel)"
    report(f"rendering {name} at {args.resolution}x{args.resolution} under {lighting} ...")
    image = render_sphere(material, resolution=args.resolution, light=args.light, light_intensity=args.light_intensity,
                          model=args.model, environment=environment, samples=args.samples,
                          energy_compensation=args.energy_compensation)
    with _naming_the_output(args.output):
        save_image(args.output, image, exposure=args.exposure, curve=args.tone)
    report(f"wrote {args.output}")


def _bench(args: argparse.Namespace, report: Callable[[str], object]) -> None:
    from .benchmark import compare_with_numpy

    compare_with_numpy(pairs=args.pairs, repeats=args.repeats, report=report)


def _info(args: argparse.Namespace, report: Callable[[str], object]) -> None:
    from . import __version__
    from ._batch import cpu_info

    info = cpu_info()
    report(f"principled-brdf {__version__}")
    report(f"instruction set: {info['isa']} ({info['float_lanes']} float lanes); "
           f"available: {', '.join(info['available'])} (force one with PRINCIPLED_BRDF_ISA)")
    report(f"threads: {info['threads']}")
    report(f"python {platform.python_version()}, numpy {np.__version__}, {platform.machine()}, {platform.system()}")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="python -m principled_brdf",
                                     description="Disney principled BRDF: SIMD evaluation and sampling.")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)

    demo = commands.add_parser("demo", help="evaluate and sample millions of pairs, print throughput, write a picture",
                               description="The README's main job: evaluate and sample millions of random pairs, "
                                           "print throughput beside the memory roofline, write a picture.")
    demo.add_argument("--pairs", type=_at_most(MAX_PAIRS, "pairs"), default=1 << 22,
                      help="pairs to evaluate (default 4194304)")
    demo.add_argument("--repeats", type=_at_most(MAX_REPEATS, "repeats"), default=5,
                      help=f"timed runs, best kept (default 5, at most {MAX_REPEATS})")
    demo.add_argument("--output", type=_image_path((".png",)), default="principled_brdf_demo.png",
                      help="picture to write (PNG)")
    demo.add_argument("--resolution", type=_at_most(MAX_RESOLUTION, "pixels", lower=MIN_PICTURE_RESOLUTION),
                      default=PICTURE_RESOLUTION,
                      help=f"pixels per sphere of the picture (default {PICTURE_RESOLUTION}, {MIN_PICTURE_RESOLUTION} to "
                           f"{MAX_PICTURE_RESOLUTION}: {PICTURE_SPHERES} spheres x resolution² x {PICTURE_SAMPLES} "
                           f"samples at most 2^32)")
    demo.set_defaults(run=_demo, limits=_demo_limits)

    render = commands.add_parser("render", help="render a preset or parameters on a lit sphere (PNG, EXR, NPY)",
                                 description="Render a material on a sphere lit by an environment (and a key light).")
    from . import presets
    from .render import DEFAULT_MAP_SAMPLES, DEFAULT_SAMPLES, IMAGE_FORMATS, TONE_CURVES

    render.add_argument("--preset", choices=presets.names(), help="start from a named preset")
    render.add_argument("--merl", metavar="PATH.binary",
                        help="render measured data, a MERL file, instead of a material (no --preset, --param, "
                             "--model or --energy-compensation)")
    render.add_argument("--param", action="append", type=_parameter, metavar="NAME=VALUE",
                        help="set a parameter (repeatable), e.g. roughness=0.3 or base_color=0.9,0.6,0.2")
    render.add_argument("--resolution", type=_at_most(MAX_RESOLUTION, "pixels", lower=2), default=512,
                        help="image size in pixels (default 512)")
    render.add_argument("--environment", type=_environment, default="studio", metavar="ENVIRONMENT",
                        help="the light all around: studio (default: softboxes in a dark studio), outdoor (sky, sun, "
                             "a tiled ground), sky (a plain gradient), none, or a latitude-longitude map PATH.exr or "
                             "PATH.hdr")
    render.add_argument("--no-environment", dest="environment", action="store_const", const="none",
                        help="the same as --environment none: the key light alone")
    render.add_argument("--light", type=_vector, default=(-0.5, 0.6, 0.75),
                        help="direction towards the key light, camera space x,y,z (default -0.5,0.6,0.75)")
    render.add_argument("--light-intensity", type=_intensity, default=None,
                        help="the key light's irradiance (default 3 with sky or none, 0 with a map: it brings its "
                             "own lights)")
    render.add_argument("--samples", type=_at_most(MAX_SAMPLES, "samples per pixel"), default=None,
                        help=f"environment samples per pixel (default {DEFAULT_SAMPLES} with sky, "
                             f"{DEFAULT_MAP_SAMPLES} with a map; at most {MAX_SAMPLES}, and resolution² x samples "
                             "at most 2^34)")
    render.add_argument("--exposure", type=_exposure, default=1.0,
                        help="scale before tone mapping, or of the linear values in EXR/NPY (default 1)")
    render.add_argument("--tone", choices=TONE_CURVES, default="filmic",
                        help="the tone curve of a PNG (default filmic; EXR and NPY stay linear)")
    render.add_argument("--energy-compensation", action=argparse.BooleanOptionalAction, default=False,
                        help="add the multiple-scattering lobe of rough metals (default off)")
    render.add_argument("--model", choices=_models.MODEL_NAMES, default=_models.DEFAULT_MODEL,
                        help="disney2014 (default), disney2012, or the 2015 BSDF: disney2015 (a solid sphere, light "
                             "refracted through it), disney2015_thin (a thin shell)")
    render.add_argument("--output", required=True, type=_image_path(tuple(IMAGE_FORMATS)),
                        help="file to write: .png (tone mapped, sRGB), .exr or .npy (linear float32)")
    render.set_defaults(run=_render, limits=_render_limits)

    bench = commands.add_parser("bench", help="compare pb.eval with a numpy float32 implementation",
                                description="Time pb.eval against a straightforward numpy float32 implementation "
                                            "of the model on the same pairs.")
    bench.add_argument("--pairs", type=_at_most(MAX_PAIRS, "pairs"), default=1 << 22, help="pairs (default 4194304)")
    bench.add_argument("--repeats", type=_at_most(MAX_REPEATS, "repeats"), default=5,
                       help=f"timed runs, best kept (default 5, at most {MAX_REPEATS})")
    bench.set_defaults(run=_bench, limits=_timing_limits)

    info = commands.add_parser("info", help="instruction set, threads and versions",
                               description="Show the instruction set in use, threads and versions.")
    info.set_defaults(run=_info)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    limits = getattr(args, "limits", None)
    problem = limits(args) if limits is not None else None
    if problem is not None:
        print(f"{parser.prog} {args.command}: error: {problem}", file=sys.stderr)
        return 2
    report = _Progress()
    try:
        args.run(args, report)
    except (ValueError, TypeError, OSError) as error:
        print(f"{parser.prog} {args.command}: error: {error}", file=sys.stderr)
        return 2
    except MemoryError:
        print(f"{parser.prog} {args.command}: error: not enough memory for this job", file=sys.stderr)
        return 2
    return 0

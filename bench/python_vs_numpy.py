"""principled_brdf.eval against a straightforward numpy float32 implementation
of the model (docs/model.md, "The model") on the same pairs (default 4M), uniform material, timed in one
process. The implementation lives in principled_brdf.benchmark (also
`python -m principled_brdf bench`).

    python bench/python_vs_numpy.py [--pairs 4194304] [--repeats 5]
"""

import argparse

from principled_brdf.benchmark import compare_with_numpy

if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pairs", type=int, default=1 << 22)
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    compare_with_numpy(args.pairs, args.repeats)

"""A call whose f is larger than the last-level cache (32 MB: 2,796,203 pairs
or more) writes f by non-temporal stores from the first register-aligned
element: the same values, bit for bit, as calls small enough to use ordinary
stores, whatever the output's alignment, the thread count, the lobe set, and
with the direction check stopping at the right element."""

import numpy as np
import pytest

import principled_brdf as pb
from conftest import random_direction_pairs, seeded_rng

ISAS = pb.cpu_info()["available"]
STREAMED = 3_000_001  # f: 36 MB, past the batch layer's 32 MB
PIECE = 250_000       # 3 MB: ordinary stores


def in_pieces(material, wi, wo, isa, **options):
    return np.concatenate([pb.eval(material, wi[s:s + PIECE], wo[s:s + PIECE], isa=isa, **options)
                           for s in range(0, len(wi), PIECE)])


@pytest.fixture(scope="module")
def pairs():
    rng = seeded_rng("streaming")
    return tuple(w.astype(np.float32) for w in random_direction_pairs(rng, STREAMED))


@pytest.mark.parametrize("isa", ISAS)
@pytest.mark.parametrize("material", [pb.Material(base_color=(0.82, 0.67, 0.16), metallic=0.2, subsurface=0.3,
                                                  roughness=0.4, sheen=0.5, clearcoat=0.5, anisotropic=0.3),
                                      pb.presets.get("gold")])
def test_a_streamed_call_matches_calls_in_pieces(pairs, isa, material):
    wi, wo = pairs
    expected = in_pieces(material, wi, wo, isa)
    backing = np.full((STREAMED + 16, 3), np.nan, dtype=np.float32)
    for offset in (0, 1, 5):  # three starts, 12 bytes a row apart: a different head before the first aligned row
        out = backing[offset:offset + STREAMED]
        for threads in (1, 2):
            out[:] = np.nan
            pb.eval(material, wi, wo, out=out, threads=threads, isa=isa)
            np.testing.assert_array_equal(out, expected)
    np.testing.assert_array_equal(pb.eval(material, wi, wo, isa=isa, energy_compensation=True),
                                  in_pieces(material, wi, wo, isa, energy_compensation=True))


@pytest.mark.parametrize("isa", ISAS)
def test_a_streamed_call_names_its_first_bad_direction(pairs, isa):
    wi, wo = pairs
    bad = wi.copy()
    bad[2_000_017] *= 1.01
    with pytest.raises(ValueError, match=r"wi\[2000017\]: length 1.01 is not 1"):
        pb.eval(pb.presets.get("gold"), bad, wo, threads=2, isa=isa)

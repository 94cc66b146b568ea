"""Material(ior=...) sets specular from an index of refraction and Material.ior
reads it back (docs/materials-and-directions.md)."""

import numpy as np
import pytest

import principled_brdf as pb


def test_ior_round_trip():
    eta = np.array([1.0, 1.33, 1.5, 2.4, 4.0])
    m = pb.Material(ior=eta)
    np.testing.assert_allclose(m.specular, ((eta - 1) / (eta + 1)) ** 2 / 0.08, rtol=1e-15)
    np.testing.assert_allclose(m.ior, eta, rtol=1e-13)
    assert float(pb.Material(ior=1.5).specular) == pytest.approx(0.5, rel=1e-15)
    assert float(pb.Material().ior) == pytest.approx(1.5, rel=1e-14)
    assert float(pb.Material(specular=12.5).ior) == np.inf
    assert float(pb.Material().replace(ior=1.33).specular) == pytest.approx(((0.33 / 2.33) ** 2) / 0.08)
    # F0 of the dielectric at normal incidence is the Fresnel factor of that index
    np.testing.assert_allclose(0.08 * m.specular, pb.microfacet.fresnel_dielectric(1.0, eta), rtol=1e-13)


@pytest.mark.parametrize("kwargs, message", [({"ior": 0.9}, r"ior: 0.9 is outside its domain \[1, inf\)"),
                                             ({"ior": np.nan}, r"ior: nan"),
                                             ({"ior": 1.5, "specular": 0.3}, r"ior: give specular or ior")])
def test_bad_ior(kwargs, message):
    with pytest.raises(ValueError, match=message):
        pb.Material(**kwargs)

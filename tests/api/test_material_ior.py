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


@pytest.mark.parametrize("kwargs, message", [({"ior": 0.9}, r"ior: 0.9 is outside its domain \[1, 10\]"),
                                             ({"ior": 1e300}, r"ior: 1e\+300 is outside its domain \[1, 10\]"),
                                             ({"ior": [1.5, 10.000001]}, r"ior\[1\]: 10.000001 is outside its domain"),
                                             ({"ior": np.nan}, r"ior: nan"),
                                             ({"ior": 1.5, "specular": 0.3}, r"ior: give specular or ior")])
def test_bad_ior(kwargs, message):
    with pytest.raises(ValueError, match=message):
        pb.Material(**kwargs)


@pytest.mark.parametrize("model", ["disney2015", "disney2015_thin"])
def test_the_2015_models_take_every_ior_up_to_the_limit(model):
    """From η = MAX_IOR on the float32 kernels would lose their accuracy (near the critical angle
    from inside) and from specular 12.5 on η is infinite (NaN in float32): the domain ends at
    MAX_IOR, inclusive, and a specular beyond it is refused naming specular and the limit."""
    from principled_brdf.material import MAX_BSDF_SPECULAR, MAX_IOR
    m = pb.Material(base_color=(1, 1, 1), spec_trans=1, roughness=0.3, ior=MAX_IOR)
    assert float(m.specular) == MAX_BSDF_SPECULAR
    wi, wo = np.float32([[0, -0.6, 0.8], [0, -0.6, -0.8]]), np.float32([[0, 0.6, 0.8], [0, 0.6, 0.8]])
    for isa in pb.cpu_info()["available"]:
        f = pb.eval(m, wi, wo, model=model, isa=isa)
        np.testing.assert_allclose(f, pb.reference.eval(m, wi, wo, model=model), rtol=1e-4)
        assert np.isfinite(pb.eval_grad(m, wi, wo, model=model, isa=isa).jacobian).all()
        s = pb.sample(m, np.tile(wo[:1], (1000, 1)), seed=1, model=model, isa=isa)
        assert np.isfinite(s.weight).all() and (s.pdf > 0).mean() > 0.5  # most views of the sheet draw a sample
    for specular in (np.nextafter(MAX_BSDF_SPECULAR, 13.0), 12.49999, 12.5):
        with pytest.raises(ValueError, match=rf"specular: model '{model}' needs specular <= 8.36777 \(an index of "
                                             r"refraction up to MAX_IOR = 10\)"):
            pb.eval(pb.Material(specular=specular), wi, wo, model=model)

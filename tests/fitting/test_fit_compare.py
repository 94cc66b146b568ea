"""FitResult.compare: the data and the fit rendered side by side through the same
estimator on the same points, so that a fit that reproduces the data shows no
difference at all and a wrong one shows its error."""

import matplotlib
import numpy as np
import pytest

import principled_brdf as pb

matplotlib.use("Agg")

GOLD = pb.Material(base_color=(0.9, 0.6, 0.25), metallic=1.0, roughness=0.35)
PAIRS = pb.measured.merl_pairs(step=6)


def data_of(material):
    return lambda wi, wo: pb.reference.eval(material, wi, wo)


def fitted(material):
    wi, wo = PAIRS
    return pb.fit(wi, wo, pb.reference.eval(material, wi, wo))


def test_a_fit_that_reproduces_the_data_shows_no_difference():
    result = fitted(GOLD)
    comparison = result.compare(data_of(GOLD), resolution=32, samples=32)
    assert comparison.environments == ("studio", "outdoor")
    assert comparison.data.shape == comparison.fit.shape == (2, 32, 32, 3)
    assert comparison.data.max() > 0.1
    assert max(comparison.image_error) < 1e-4, comparison.image_error


def test_a_wrong_fit_shows_its_error():
    result = fitted(GOLD.replace(roughness=0.55))
    comparison = result.compare(data_of(GOLD), resolution=32, samples=32, environments=["studio"])
    assert comparison.image_error[0] > 0.1, comparison.image_error


def test_the_figure_draws_data_fit_and_difference_per_environment():
    comparison = fitted(GOLD).compare(data_of(GOLD), resolution=16, samples=8)
    figure = comparison.figure()
    titles = [axis.get_title() for axis in figure.axes]
    assert len(titles) == 6 and titles[0] == "data, studio" and titles[4] == "fit, outdoor"
    assert "image error" in titles[2]


def test_a_batched_fit_shows_the_texel_asked_for():
    wi, wo = PAIRS
    materials = [GOLD, GOLD.replace(roughness=0.6)]
    measured = np.stack([pb.reference.eval(m, wi, wo) for m in materials])
    result = pb.fit(wi, wo, measured)
    with pytest.raises(ValueError, match="texel"):
        result.compare(data_of(materials[1]), resolution=16, samples=8)
    second = result.compare(data_of(materials[1]), texel=1, resolution=16, samples=8)
    first = result.compare(data_of(materials[1]), texel=0, resolution=16, samples=8)
    assert max(second.image_error) < 1e-3 < min(first.image_error)


def test_cells_without_data_are_left_out_of_both_pictures():
    """Data missing half its pairs against the material that made it: no difference."""
    result = fitted(GOLD)
    complete = data_of(result.material)

    def half_missing(wi, wo):
        return np.where(wi[..., :1] > 0.0, np.nan, complete(wi, wo))
    comparison = result.compare(half_missing, resolution=24, samples=16)
    assert max(comparison.image_error) < 1e-4


def test_bad_data_is_a_named_error():
    result = fitted(GOLD)
    with pytest.raises(ValueError, match="^data:"):
        result.compare(lambda wi, wo: -np.ones(np.broadcast(wi, wo).shape), resolution=8, samples=4)
    with pytest.raises(TypeError, match="^data:"):
        result.compare(3, resolution=8, samples=4)
    with pytest.raises(ValueError, match="^data: the callable returned f of shape|^data: expected the callable"):
        result.compare(lambda wi, wo: np.ones(np.broadcast(wi, wo).shape[:-1]), resolution=8, samples=4)
    with pytest.raises(ValueError, match="^data: no value"):
        result.compare(lambda wi, wo: np.full(np.broadcast(wi, wo).shape, np.nan), resolution=8, samples=4)
    with pytest.raises(ValueError, match="environments"):
        result.compare(data_of(GOLD), environments="studio", resolution=8, samples=4)

"""Bad values of sequence and seed parameters are ValueError/TypeError naming
the parameter, not raw numpy or Python messages (issue 30's remaining raw
errors)."""
import numpy as np
import pytest

import fractalgeo_rs as fg

Z = fg.fbm_surface((64, 64), 0.7, seed=1)
MASK = Z > 0
PROFILE = fg.fbm(256, 0.6, seed=1)


@pytest.mark.parametrize("call, name", [
    (lambda v: fg.blanket(Z, epsilons=v), "epsilons"),
    (lambda v: fg.lacunarity(MASK, box_sizes=v), "box_sizes"),
    (lambda v: fg.mass_dimension(MASK, box_sizes=v), "box_sizes"),
    (lambda v: fg.minkowski(MASK, radii=v), "radii"),
    (lambda v: fg.self_affine_box_counting(Z, scale_range=v), "scale_range"),
    (lambda v: fg.wavelet_dimension(Z, levels=v), "levels"),
    (lambda v: fg.scale_space(PROFILE, sigmas=v), "sigmas"),
    (lambda v: fg.validate_surface(Z, 0.7, lags=v), "lags"),
])
@pytest.mark.parametrize("value", [1.5, -1, 10**9, "x", np.nan, True, []])
def test_sequence_parameters_name_themselves(call, name, value):
    with pytest.raises((ValueError, TypeError)) as e:
        call(value)
    assert str(e.value).startswith(f"{name}:"), str(e.value)


def test_segment_seed_and_spectral_bins():
    with pytest.raises(TypeError, match="^seed:"):
        fg.segment([Z, -Z], method="kmeans", n_classes=2, seed=1.5)
    with pytest.raises(ValueError, match="^seed:"):
        fg.segment([Z, -Z], method="kmeans", n_classes=2, seed=-1)
    with pytest.raises(ValueError, match="^n_bins:"):
        fg.spectral_dimension(Z, n_bins=10**9)
    with pytest.raises(TypeError, match="^latitude:"):
        fg.hillshade(Z, latitude="x")


def test_validate_surface_on_a_small_grid_has_no_spectral_slope():
    r = fg.validate_surface(fg.fbm_surface((32, 32), 0.7, seed=1), 0.7)
    assert np.isnan(r.spectral_slope) and np.isnan(r.hurst_spectrum) and np.isfinite(r.hurst_variogram)


def test_auto_scale_range_on_two_scales_names_scale_range():
    with pytest.raises(ValueError, match="^scale_range: 'auto' picks a range of at least 3"):
        fg.variogram(Z, scale_range="auto")

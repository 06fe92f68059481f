"""The two-sided leaf of canopy scenes (kernel ``rust/radiometry/bilambertian.rs``)."""
from __future__ import annotations

import numbers
from dataclasses import dataclass
from typing import List, Tuple

__all__ = ["BiLambertian"]


def _fraction(value, name: str) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name}: expected a number in [0, 1], got {value!r}")
    v = float(value)
    if not 0.0 <= v <= 1.0:  # also rejects NaN
        raise ValueError(f"{name}: expected a fraction in [0, 1], got {v}")
    return v


@dataclass(frozen=True)
class BiLambertian:
    """A thin two-sided leaf: diffuse reflection into the side the light
    comes from, diffuse transmission into the other.

    The BSDF is ``reflectance / pi`` (1/sr) for directions on the same side
    of the facet and ``transmittance / pi`` for directions on opposite
    sides, so a leaf lit from either side reflects the fraction
    ``reflectance`` and transmits ``transmittance`` of the light it
    intercepts and absorbs the rest. Reciprocal; energy conservation needs
    ``reflectance + transmittance <= 1`` (equal to 1: a conservative,
    non-absorbing leaf, as in RAMI's "purist corner").

    Light reaches the far side only in scenes of two-sided facets (meshes);
    a heightfield (``Scene.from_dem``) is opaque and does not accept it.

    Parameters
    ----------
    reflectance : float
        Hemispherical reflectance ``r`` in [0, 1].
    transmittance : float
        Hemispherical transmittance ``t`` in [0, 1], ``r + t <= 1``.

    Raises
    ------
    ValueError
        A value outside [0, 1] (naming it), or ``reflectance +
        transmittance > 1`` (naming ``transmittance``).

    Examples
    --------
    >>> from fractalgeo_rs.radiometry import BiLambertian
    >>> leaf = BiLambertian(0.45, 0.45)
    >>> leaf, leaf.albedo
    (BiLambertian(reflectance=0.45, transmittance=0.45), 0.9)

    References
    ----------
    B. Pinty et al., "Radiation transfer model intercomparison (RAMI)
    exercise", *J. Geophys. Res.* 106(D11) (2001) 11937-11956,
    doi:10.1029/2000JD900493 (bi-Lambertian scatterers of the RAMI scenes).
    """

    reflectance: float
    transmittance: float = 0.0

    def __post_init__(self):
        r = _fraction(self.reflectance, "reflectance")
        t = _fraction(self.transmittance, "transmittance")
        if r + t > 1.0:
            raise ValueError(f"transmittance: expected reflectance + transmittance <= 1 (energy conservation), "
                             f"got {r} + {t} = {r + t}")
        object.__setattr__(self, "reflectance", r)
        object.__setattr__(self, "transmittance", t)

    @property
    def albedo(self) -> float:
        """The scattered fraction ``reflectance + transmittance``."""
        return self.reflectance + self.transmittance

    def _spec(self) -> Tuple[str, List[float]]:
        return "bilambertian", [self.reflectance, self.transmittance]

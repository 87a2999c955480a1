"""The reflector's surface (model.surface): the material presets and the mixed coupling."""

import numpy as np
import pytest

from reflector_opt.design import default_design
from reflector_opt.model._surface import (
    DEFAULT_MATERIAL,
    MATERIALS,
    SurfaceCoupling,
    get_material,
)
from reflector_opt.util._errors import InputError


def test_presets_and_their_lookup():
    assert get_material("polished").specular_fraction == 1.0
    assert get_material("matte").specular_fraction == 0.0
    resin = get_material(DEFAULT_MATERIAL)
    # Fresnel at n = 1.5, ((n − 1)/(n + 1))² = 0.04, over ρ = 0.9: f = 0.044, rounded to 0.05.
    assert ((1.5 - 1) / (1.5 + 1)) ** 2 / resin.reflectance == pytest.approx(0.0444, abs=1e-4)
    assert (resin.reflectance, resin.specular_fraction) == (0.9, 0.05)
    # A new design is made of the default material.
    reflector = default_design().reflector
    assert (reflector.reflectance, reflector.specular_fraction) == (0.9, 0.05)
    for name, material in MATERIALS.items():
        assert material.name == name and 0 < material.reflectance <= 1 and material.source
    with pytest.raises(InputError, match=r"^unknown surface 'gold'; known surfaces: white-sla"):
        get_material("gold")


def test_total_is_reflectance_times_the_mix():
    parts = SurfaceCoupling(np.array([0.02, 0.04]), np.array([0.01, 0.005]))
    # ρ = 0.8, f = 0.25: 0.8 · (0.25 · 0.02 + 0.75 · 0.01) = 0.01; 0.8 · (0.01 + 0.00375) = 0.011
    np.testing.assert_allclose(parts.total(0.8, 0.25), [0.010, 0.011], rtol=1e-12)
    np.testing.assert_allclose(parts.total(1.0, [1.0, 0.0]), [0.02, 0.005], rtol=1e-12)

"""The reflector's surface: a mirror-like share and a Lambertian share of its reflectance.

A surface of reflectance ρ (``reflector.reflectance``) returns the fraction ρ of the light
that reaches it; the share f (``reflector.specular_fraction``) of that is reflected as by a
mirror and the rest, 1 − f, diffusely with Lambert's cosine law, so the coupling of a sensor
is ``η = ρ · [f · η_mirror + (1 − f) · η_Lambert]`` (docs/model.md, "Surface model").

The reference paper prints its reflector in white SLA resin: a smooth dielectric surface
whose Fresnel reflection (about 4 % at normal incidence for n ≈ 1.5) is the mirror-like part,
over a strongly scattering, translucent body that returns most of the rest diffusely. The
presets below name such materials with their values and sources (docs/model.md lists them).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from reflector_opt.util._errors import InputError

if TYPE_CHECKING:  # the presets import without numpy, so the command line's help is quick
    import numpy as np


@dataclass(frozen=True)
class Material:
    """A reflector surface: its reflectance, specular fraction and where the values come from.

    Parameters
    ----------
    name : str
        Preset name.
    reflectance : float
        Total reflectance ρ in the near infrared (0–1).
    specular_fraction : float
        Share f of ρ that is mirror-like (0–1).
    source : str
        Where the values come from.
    """

    name: str
    reflectance: float
    specular_fraction: float
    source: str


#: Material presets (docs/model.md, "Surface model", gives the reasoning).
MATERIALS = {
    m.name: m
    for m in (
        Material(
            "white-sla-resin",
            0.9,
            0.05,
            "Fresnel reflectance of a smooth dielectric of n ≈ 1.5 at near-normal incidence, "
            "((n − 1)/(n + 1))² ≈ 0.04 (Hecht, Optics, 5th ed., §4.6), over a white, strongly "
            "scattering body; total 0.9 as assumed for the paper's white SLA part. f = 0.04/0.9 "
            "rounded to 0.05. Measure your resin with `reflector-opt fit-sensor`.",
        ),
        Material(
            "polished",
            0.9,
            1.0,
            "A polished or metallised part: all of ρ mirror-like (the model of earlier "
            "versions of this tool).",
        ),
        Material(
            "matte",
            0.9,
            0.0,
            "A matte, diffusely reflecting part (e.g. bead-blasted or white-painted): all of ρ "
            "Lambertian.",
        ),
    )
}


#: The material of a new design: the paper's printed part.
DEFAULT_MATERIAL = "white-sla-resin"


def get_material(name):
    """Look up a material preset by name.

    Parameters
    ----------
    name : str
        One of :data:`MATERIALS` (``"white-sla-resin"``, ``"polished"``, ``"matte"``).

    Returns
    -------
    Material
    """
    try:
        return MATERIALS[name]
    except KeyError:
        raise InputError(
            f"unknown surface {name!r}; known surfaces: {', '.join(MATERIALS)}"
        ) from None


@dataclass(frozen=True)
class SurfaceCoupling:
    """Couplings of a fully mirror-like and a fully Lambertian surface of reflectance 1.

    Attributes
    ----------
    mirror, lambertian : numpy.ndarray or float
        Detected over emitted power (dimensionless).
    """

    mirror: np.ndarray
    lambertian: np.ndarray

    def total(self, reflectance, specular_fraction):
        """Coupling of a surface of reflectance ρ and specular fraction f.

        ``η = ρ · [f · η_mirror + (1 − f) · η_Lambert]``.

        Parameters
        ----------
        reflectance : float or array_like
            ρ (0–1).
        specular_fraction : float or array_like
            f (0–1).

        Returns
        -------
        numpy.ndarray
        """
        import numpy as np

        f = np.asarray(specular_fraction, dtype=float)
        return reflectance * (f * self.mirror + (1.0 - f) * self.lambertian)

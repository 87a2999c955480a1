"""A simulated print process: a systematic deviation that repeats, and the tolerances' scatter.

An SLA printer does not print a part as drawn. Part of the deviation repeats from print to
print — the resin shrinks as it cures, supports and layer steps move features the same way
each time, a seat comes out tilted — and part of it is different for every unit.
:class:`PrintProcess` models both, for the tests and the benchmark of the print loop
(docs/print-loop.md):

* the **systematic part**, applied to the drawn geometry in this order:

  1. an isotropic shrink by the fraction ``shrink`` about the unit's origin O (the spherical
     bearing's centre): every length and position is scaled by ``1 − shrink`` — the
     reflecting sphere's radius and centre, the shell's inner radius and each sensor's seat
     position (axes keep their direction);
  2. the sphere's radius changed by ``radius_change_mm`` and its centre moved by
     ``centre_shift_mm``;
  3. each sensor's seat tilted by ``seat_tilts_deg[k]`` = (towards its detector, sideways),
     degrees, in the sensor's own frame (:func:`reflector_opt.asbuilt._parameters.sensor_frame`,
     the identification's ``tilt_led_detector`` and ``tilt_sideways``), and moved along its
     axis by ``seat_standoffs_mm[k]`` (positive away from the reflector: a deeper seat);

* the **random part**: each unit drawn about that systematic geometry by
  :func:`reflector_opt.tolerance._builtunit.build_unit` with ``tolerances`` (default the tolerance
  model's), its optics exact — and, with ``model_form``, with physics the fast model lacks;
  the units of one batch share one surface (``surface``, default the design's reflectance
  and specular fraction).

The defaults — shrink 0.6 %, sphere centre +40 µm in z, sensor 1's seat tilted 0.8° towards
its detector — are of the size reported for SLA parts (isotropic shrink of a few tenths of a
percent, tens of µm of support-side offset, a degree of seat tilt); they are assumptions of
the benchmark, not a measured printer.
"""

from dataclasses import dataclass, field, replace

import numpy as np

from reflector_opt.asbuilt._correction import changed_geometry
from reflector_opt.asbuilt._parameters import true_deviations
from reflector_opt.model._noise import Mismatch
from reflector_opt.tolerance._builtunit import build_unit
from reflector_opt.tolerance._tolerances import Tolerances
from reflector_opt.util._errors import InputError

#: Largest isotropic shrink (or growth, negative) accepted, as a fraction.
MAX_SHRINK = 0.1


def _checked_fields(process):
    """The fields of a :class:`PrintProcess` checked and normalised (floats, tuples), by
    name; InputError on the first out of range."""
    shrink = float(process.shrink)
    if not (np.isfinite(shrink) and abs(shrink) <= MAX_SHRINK):
        raise InputError(f"shrink: expected −{MAX_SHRINK:g} to {MAX_SHRINK:g}, got {shrink!r}")
    shift = np.asarray(process.centre_shift_mm, dtype=float)
    if shift.shape != (3,) or not np.isfinite(shift).all():
        raise InputError(f"centre_shift_mm: expected 3 finite numbers, got {shift.tolist()}")
    tilts = np.asarray(process.seat_tilts_deg, dtype=float).reshape(-1, 2)
    if not (np.isfinite(tilts).all() and np.all(np.abs(tilts) < 30.0)):
        raise InputError("seat_tilts_deg: expected (towards detector, sideways) pairs, |·| < 30°")
    radius = float(process.radius_change_mm)
    if not (np.isfinite(radius) and abs(radius) < 1.0):
        raise InputError(f"radius_change_mm: expected a number, |·| < 1 mm, got {radius!r}")
    standoffs = np.asarray(process.seat_standoffs_mm, dtype=float).reshape(-1)
    if not (np.isfinite(standoffs).all() and np.all(np.abs(standoffs) < 1.0)):
        raise InputError("seat_standoffs_mm: expected numbers, |·| < 1 mm")
    return {
        "seat_standoffs_mm": tuple(standoffs.tolist()),
        "shrink": shrink,
        "centre_shift_mm": tuple(shift.tolist()),
        "seat_tilts_deg": tuple(map(tuple, tilts.tolist())),
        "radius_change_mm": radius,
    }


def _scaled(design, scale):
    """``design`` scaled about the origin O by ``scale``: the sphere, the shell and the
    sensors' positions (their axes kept)."""
    reflector = design.reflector
    return design.replace(
        reflector=replace(
            reflector,
            radius_mm=reflector.radius_mm * scale,
            centre_mm=tuple((np.asarray(reflector.centre_mm) * scale).tolist()),
            inner_radius_mm=reflector.inner_radius_mm * scale,
        ),
        sensors=tuple(
            replace(s, position_mm=tuple((np.asarray(s.position_mm) * scale).tolist()))
            for s in design.sensors
        ),
    )


def _systematic_change(process, n_sensors):
    """The process's radius change, centre shift and the seats' tilts and standoffs of the
    first ``n_sensors`` sensors, by as-built parameter name (mm, degrees)."""
    change = {"reflector_radius_mm": process.radius_change_mm}
    for axis, shift in zip("xyz", process.centre_shift_mm, strict=True):
        change[f"reflector_centre_{axis}_mm"] = shift
    for k, (towards, sideways) in enumerate(process.seat_tilts_deg[:n_sensors]):
        change[f"sensor_{k + 1}_tilt_led_detector_deg"] = towards
        change[f"sensor_{k + 1}_tilt_sideways_deg"] = sideways
    for k, standoff in enumerate(process.seat_standoffs_mm[:n_sensors]):
        change[f"sensor_{k + 1}_standoff_mm"] = standoff
    return change


@dataclass(frozen=True)
class PrintProcess:
    """A print process: systematic deviation plus the tolerance model's unit-to-unit scatter.

    Parameters
    ----------
    shrink : float
        Isotropic shrink about the origin O, a fraction (0.006 = 0.6 %; negative: growth).
    centre_shift_mm : (float, float, float)
        Shift of the reflecting sphere's centre after the shrink, mm.
    seat_tilts_deg : tuple of (float, float)
        Per sensor, in design order, the seat's tilt (towards its detector, sideways),
        degrees; sensors beyond the tuple are not tilted.
    seat_standoffs_mm : tuple of float
        Per sensor, the seat moved along its axis, mm, positive away from the reflector
        (default none).
    tolerances : reflector_opt.tolerance._tolerances.Tolerances, optional
        The unit-to-unit scatter (default: the tolerance model's defaults).
    model_form : reflector_opt.tolerance._model_form.ModelForm, optional
        Physics of the built units beyond the fast model, passed to
        :func:`~reflector_opt.tolerance._builtunit.build_unit` (default None: the exact
        reference's physics).
    surface : (float, float), optional
        ``(reflectance, specular_fraction)`` shared by a batch's units (default: the
        design's).
    radius_change_mm : float
        Change of the reflecting sphere's radius after the shrink, mm (default none).
    """

    shrink: float = 0.006
    centre_shift_mm: tuple = (0.0, 0.0, 0.04)
    seat_tilts_deg: tuple = ((0.8, 0.0),)
    seat_standoffs_mm: tuple = ()
    tolerances: Tolerances = field(default_factory=Tolerances)
    model_form: object = None
    surface: tuple | None = None
    radius_change_mm: float = 0.0

    def __post_init__(self):
        for name, value in _checked_fields(self).items():
            object.__setattr__(self, name, value)

    @classmethod
    def scatter_only(cls, **options):
        """A process without systematic deviation: the tolerance model's scatter alone.

        Parameters
        ----------
        **options
            ``tolerances``, ``model_form``, ``surface`` (see :class:`PrintProcess`).

        Returns
        -------
        PrintProcess
        """
        return cls(
            shrink=0.0,
            centre_shift_mm=(0.0, 0.0, 0.0),
            seat_tilts_deg=(),
            seat_standoffs_mm=(),
            radius_change_mm=0.0,
            **options,
        )

    def systematic_design(self, design):
        """The geometry every unit of ``design`` is printed about: the systematic part alone.

        Parameters
        ----------
        design : reflector_opt.design._design.Design
            The drawn geometry.

        Returns
        -------
        reflector_opt.design._design.Design
            Raises :class:`~reflector_opt.util._errors.InputError` if a sensor would touch
            the sphere.
        """
        change = _systematic_change(self, len(design.sensors))
        return changed_geometry(_scaled(design, 1.0 - self.shrink), list(change), change.values())

    def systematic_deviation(self, design):
        """The systematic part as one unit's block of as-built parameters (read-out zero).

        Parameters
        ----------
        design : reflector_opt.design._design.Design

        Returns
        -------
        numpy.ndarray
            The block of :class:`~reflector_opt.asbuilt._parameters.ParameterLayout` (mm, degrees).
        """
        n = len(design.sensors)
        nominal = Mismatch((1.0,) * n, (0.0,) * n)
        return true_deviations(design, self.systematic_design(design), nominal)

    def print_unit(self, design, index, seed=0):
        """Print one unit of ``design``: the systematic part, then this unit's scatter.

        Parameters
        ----------
        design : reflector_opt.design._design.Design
            The drawn geometry (e.g. a corrected design).
        index : int
            The unit's draw index.
        seed : int
            Seed of the batch's scatter.

        Returns
        -------
        reflector_opt.tolerance._builtunit.BuiltUnit
        """
        surface = self.surface
        if surface is None:
            surface = (design.reflector.reflectance, design.reflector.specular_fraction)
        return build_unit(
            self.systematic_design(design),
            index,
            seed=seed,
            tolerances=self.tolerances,
            model_form=self.model_form,
            surface=tuple(surface),
        )

    def print_batch(self, design, n_units, seed=0, first_index=0):
        """Print a batch of units of ``design``.

        Parameters
        ----------
        design : reflector_opt.design._design.Design
        n_units : int
            Units in the batch (1 or more).
        seed : int
            Seed of the batch's scatter: another seed is another batch.
        first_index : int
            Draw index of the first unit.

        Returns
        -------
        list of reflector_opt.tolerance._builtunit.BuiltUnit
        """
        if isinstance(n_units, bool) or int(n_units) != n_units or n_units < 1:
            raise InputError(f"n_units: expected a whole number ≥ 1, got {n_units!r}")
        return [self.print_unit(design, first_index + i, seed=seed) for i in range(int(n_units))]

    def to_dict(self):
        """JSON-ready description (the tolerances as the tolerance config writes them)."""
        return {
            "shrink": self.shrink,
            "centre_shift_mm": list(self.centre_shift_mm),
            "seat_tilts_deg": [list(t) for t in self.seat_tilts_deg],
            "seat_standoffs_mm": list(self.seat_standoffs_mm),
            "radius_change_mm": self.radius_change_mm,
            "tolerances": self.tolerances.to_dict(),
            "model_form": None if self.model_form is None else repr(self.model_form),
            "surface": None if self.surface is None else list(self.surface),
        }

"""Make the sample data in examples/data: what the lab would record of one printed segment.

The segment is the design in ``design.json`` (the one ``reflector-opt optimise`` writes for the
defaults, seed 0; the script reads it) printed as the tolerance model prints it: each of its units
is a built unit (:func:`reflector_opt.tolerance._builtunit.build_unit`: reflector radius and centre,
sensor seats, gain and offset drawn from the default tolerances, exact optics) carrying the
physics the fast model leaves out (:class:`reflector_opt.tolerance._model_form.ModelForm` at its
defaults: a rough specular lobe, sub-surface spread, a non-Gaussian emitter, crosstalk and
ambient light). The files are therefore not the fitted models' own output, as a printed
unit's would not be. Written into FOLDER (default: examples/data beside this script), beside
the ``design.json`` there::

    python examples/make_sample_data.py [FOLDER]

* ``data.csv`` — calibration data of the four units on a 2.5° grid of pitch and roll
  (13 × 13 poses each; angles as the reference reads them, its noise included), the format
  ``calibrate`` and ``identify`` read;
* ``log.csv`` — a voltage log of the segment during one cycle of the paper's ±60° pitch
  motion (50 samples), the format ``estimate`` reads;
* ``log_truth.csv`` — the poses the log was recorded at: each unit's true pitch and roll and
  the tip's (the columns of ``estimate``'s output, tip position included), to hold
  ``estimate``'s angles against (``examples/estimate_accuracy.py``);
* ``s1.csv``, ``s2.csv`` — unit 1's sensors S1 and S2 facing a flat coupon of the printed
  reflector's material, 0.3–4 mm (``identify --curve 1:S1=s1.csv``; ``fit-sensor --material``);
* ``mirror.csv`` — unit 1's sensor S1 facing a first-surface mirror (reflectance 0.87), the
  reference curve of ``fit-sensor --reflectance 0.87 --specular-fraction 1``;
* ``white.csv`` — the same sensor facing a white card (the catalogue's ``white-card``: an
  opaque diffuse target of reflectance 0.90), the reference of ``fit-sensor --target
  white-card`` and of ``fit-sensor s1.csv --material --reference white.csv``;
* ``truth.json`` — what each unit was really built as (reflector radius and centre, gains,
  offsets), to hold the commands' estimates against.

Seeded throughout, and every number rounded to a fixed number of decimals (voltages to
1 µV, below the ADC's step; angles to 0.0001°, below the reference's noise): running the
script again writes byte-identical files (tests/test_documented_commands.py checks it).
"""

from __future__ import annotations

import json
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

from reflector_opt.calibration._files import write_calibration_csv, write_voltage_log
from reflector_opt.calibration._segment import tip_angles, tip_pose, validation_motion
from reflector_opt.design import load_design
from reflector_opt.tolerance._builtunit import build_unit
from reflector_opt.tolerance._model_form import ModelForm
from reflector_opt.util._fileio import write_csv

#: Seed of the print (every unit's draw) and of the recorded noise.
SEED = 29
#: Calibration grid step, degrees.
GRID_STEP_DEG = 2.5
#: Flat-target distances, mm, as docs/guide.md says to step them for the NJL5901R-2: 0.3 to
#: 4 mm, in 0.1 mm steps through the peak and 0.2 mm steps beyond.
CURVE_DISTANCES_MM = np.round(np.concatenate([np.arange(3, 16), np.arange(8, 21) * 2]) * 0.1, 1)
#: Reflectance of the first-surface mirror the sensor is fitted to (bare aluminium, near IR).
MIRROR_REFLECTANCE = 0.87
#: Reflectance of the white card (the sensor catalogue's ``white-card`` target: the white side
#: of a Kodak grey card, 90 % diffuse).
WHITE_REFLECTANCE = 0.9
VOLT_DECIMALS = 6
ANGLE_DECIMALS = 4


def print_segment(design):
    """The built units of one printed segment, base first (seeded, form error on)."""
    return [
        build_unit(design, index, seed=SEED, model_form=ModelForm())
        for index in range(design.mechanics.n_units)
    ]


def write_calibration(path, design, units, rng):
    """Each unit recorded on the calibration grid, the reference's angle noise included."""
    pitch, roll = np.meshgrid(*design.workspace.axes(GRID_STEP_DEG), indexing="ij")
    poses = np.column_stack([pitch.ravel(), roll.ravel()])
    records = [unit.record(poses, rng) for unit in units]
    write_calibration_csv(
        path,
        np.repeat([str(i + 1) for i in range(len(units))], len(poses)),
        np.round(np.concatenate([r.volts for r in records]), VOLT_DECIMALS),
        np.round(np.concatenate([r.angles_deg for r in records]), ANGLE_DECIMALS),
    )


def log_motion(n_units):
    """Each unit's pitch and roll at each sample of the log, degrees: shape (50, n_units)."""
    return validation_motion("pitch", n_units, cycles=1, samples_per_cycle=50)


def write_log(path, units, rng):
    """The segment's voltages during one cycle of the paper's pitch motion."""
    pitch, roll = log_motion(len(units))
    volts = np.stack(
        [
            unit.record(np.column_stack([pitch[:, j], roll[:, j]]), rng, 0.0).volts
            for j, unit in enumerate(units)
        ],
        axis=1,
    )
    n_samples, n_units = pitch.shape
    write_voltage_log(
        path,
        np.repeat(np.arange(n_samples), n_units),
        np.tile([str(j + 1) for j in range(n_units)], n_samples),
        np.round(volts.reshape(-1, 2), VOLT_DECIMALS),
    )


def write_log_truth(path, design):
    """The log's true poses, in the columns ``estimate`` writes (no random draw: the other
    files are unchanged by it)."""
    pitch, roll = log_motion(design.mechanics.n_units)
    rotation, position = tip_pose(pitch, roll, design.mechanics.link_length_mm)
    tip = tip_angles(rotation)
    names = [str(j + 1) for j in range(pitch.shape[1])]
    header = ["sample", *(f"{u}_{a}_deg" for u in names for a in ("pitch", "roll"))]
    header += [f"tip_{a}_deg" for a in ("pitch", "roll", "twist")]
    header += [f"tip_{a}_mm" for a in "xyz"]
    rows = []
    for k in range(pitch.shape[0]):
        angles = np.column_stack([pitch[k], roll[k]]).ravel()
        values = np.round(np.concatenate([angles, tip[k], position[k]]), ANGLE_DECIMALS) + 0.0
        rows.append((str(k), *(repr(float(v)) for v in values)))
    write_csv(path, header, rows)


def write_curve(path, unit, sensor, rng):
    """One sensor's flat-target curve (``distance_mm,volts``)."""
    volts = np.round(unit.flat_curve(sensor, CURVE_DISTANCES_MM, rng), VOLT_DECIMALS)
    rows = (
        (repr(float(d)), repr(float(v))) for d, v in zip(CURVE_DISTANCES_MM, volts, strict=True)
    )
    write_csv(path, ("distance_mm", "volts"), rows)


def facing_a_mirror(unit):
    """The unit with a first-surface mirror for its target: no lobe, no sub-surface spread."""
    reflector = replace(
        unit.design.reflector, reflectance=MIRROR_REFLECTANCE, specular_fraction=1.0
    )
    form = unit.model_form.only("emitter_pattern", "crosstalk_coupling", "ambient_current_ua")
    return replace(unit, design=unit.design.replace(reflector=reflector), model_form=form)


def facing_a_white_card(unit):
    """The unit with a white card for its target: Lambertian, opaque (no sub-surface spread)."""
    mirror = facing_a_mirror(unit)
    reflector = replace(
        mirror.design.reflector, reflectance=WHITE_REFLECTANCE, specular_fraction=0.0
    )
    return replace(mirror, design=mirror.design.replace(reflector=reflector))


def truth(units):
    """What each unit was built as, rounded for the file."""

    def r(values):
        return [round(float(v), 6) for v in np.atleast_1d(values)]

    return {
        "seed": SEED,
        "units": [
            {
                "unit": str(i + 1),
                "reflector_radius_mm": r(u.design.reflector.radius_mm)[0],
                "reflector_centre_mm": r(u.design.reflector.centre_mm),
                "reflectance": r(u.design.reflector.reflectance)[0],
                "specular_fraction": r(u.design.reflector.specular_fraction)[0],
                "gain": r(u.mismatch.gain),
                "offset_v": r(u.mismatch.offset_v),
            }
            for i, u in enumerate(units)
        ],
    }


def make_sample_data(folder):
    """Write the sample files into ``folder``, the segment printed from its ``design.json``.

    Parameters
    ----------
    folder : str or pathlib.Path
        Holds ``design.json``.

    Returns
    -------
    list of pathlib.Path
        The files written.
    """
    folder = Path(folder)
    design = load_design(folder / "design.json")
    units = print_segment(design)
    rng = np.random.default_rng(SEED)
    write_calibration(folder / "data.csv", design, units, rng)
    write_log(folder / "log.csv", units, rng)
    write_curve(folder / "s1.csv", units[0], 0, rng)
    write_curve(folder / "s2.csv", units[0], 1, rng)
    write_curve(folder / "mirror.csv", facing_a_mirror(units[0]), 0, rng)
    write_curve(folder / "white.csv", facing_a_white_card(units[0]), 0, rng)
    (folder / "truth.json").write_text(json.dumps(truth(units), indent=2) + "\n")
    write_log_truth(folder / "log_truth.csv", design)
    return [folder / name for name in SAMPLE_FILES]


SAMPLE_FILES = (
    "data.csv",
    "log.csv",
    "s1.csv",
    "s2.csv",
    "mirror.csv",
    "white.csv",
    "truth.json",
    "log_truth.csv",
)

if __name__ == "__main__":
    target = sys.argv[1] if len(sys.argv) > 1 else Path(__file__).resolve().parent / "data"
    for written in make_sample_data(target):
        print(written)

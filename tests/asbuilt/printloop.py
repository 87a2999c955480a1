"""Batches printed by a simulated process and identified, shared by the print-loop tests.

Each batch is built once per test session (:func:`functools.cache`): a few units of a design
whose parts can be exported, calibrated on a small grid, identified together. Their angle
reference is exact (its noise aside) and anchored as such in the identification
(``reference_std=None``): these tests are about the print; tests/asbuilt/test_reference.py
corrects a batch recorded by a reference that is not.
"""

import inspect
from dataclasses import replace
from functools import cache

from reflector_opt.asbuilt._identification import identify
from reflector_opt.asbuilt._printprocess import PrintProcess
from reflector_opt.calibration._plans import make_plan
from reflector_opt.design import default_design
from reflector_opt.tolerance._builtunit import built_unit_protocol
from reflector_opt.tolerance._model_form import ModelForm

#: A process whose systematic part the calibration sees well: the seats 0.1 mm deeper and
#: shallower (2 tolerance std each), the sphere 50 µm off in x.
STRONG = PrintProcess(
    shrink=0.0,
    centre_shift_mm=(0.05, 0.0, 0.0),
    seat_tilts_deg=(),
    seat_standoffs_mm=(0.1, -0.1),
)

#: The same scatter with no systematic part.
NONE = PrintProcess.scatter_only()

#: No systematic part, but units with physics the identification's model lacks.
NONE_FORM = PrintProcess.scatter_only(model_form=ModelForm())

PROCESSES = {"strong": STRONG, "none": NONE, "none_form": NONE_FORM}

#: A seed whose "strong" batch the step search corrects. Whether it corrects a batch at all
#: depends on the units drawn (the next batch's expected loss can rise with the step: the
#: deviations bought resolution): over seeds 1–8, with the built units' draws on seed streams,
#: ``correct`` took a step above 0 on seeds 2, 3 and 4 (0.25–0.75) and 0 on the other five.
#: The tests of what a correction writes and prints need one applied.
CORRECTED_SEED = 3


def drawn_design():
    """The default design with its sphere centre at z = −1.2 mm, whose parts export."""
    design = default_design()
    return design.replace(reflector=replace(design.reflector, centre_mm=(0.0, 0.0, -1.2)))


@cache
def model_form(n_poses=49):
    """The identification's model-form biases for the drawn design (every effect)."""
    from reflector_opt.asbuilt._model_form_bias import model_form_bias

    return model_form_bias(drawn_design(), n_poses=n_poses, reference_std=None)


@cache
def printed(process, n_units=4, n_poses=49, seed=5):
    """(units, identification) of a batch printed by ``PROCESSES[process]``."""
    design = drawn_design()
    units = PROCESSES[process].print_batch(design, n_units, seed=seed)
    plan = make_plan(design.workspace, "grid", n_poses)
    samples = {}
    for unit in units:
        protocol = built_unit_protocol(unit, plan, n_validation=1, seed=seed)
        samples[str(unit.index + 1)] = (protocol.calibration.volts, protocol.calibration.angles_deg)
    options = {"profiles": False, "reference_std": None}
    if "model_form" in inspect.signature(identify).parameters:
        options["model_form"] = None  # the tests weigh the model form themselves
    return units, identify(design, samples, **options)

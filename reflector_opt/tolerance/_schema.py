"""The declared schema of a tolerance study's TOML config (``reflector-opt tolerance --config``).

:class:`ToleranceDocument` states every section and key with its type, unit, range and
default (read from :class:`~reflector_opt.tolerance._tolerances.Tolerances`,
:class:`~reflector_opt.tolerance._analysis.Settings`,
:class:`~reflector_opt.tolerance._analysis.Targets` and
:class:`~reflector_opt.tolerance._config.RunOptions`, whose defaults a test keeps equal).
What it cannot state — a calibration model's name, a Sobol size that is a power of two, the
work of the whole study — is checked by the objects built from it.
"""

from typing import Annotated

import msgspec
from msgspec import Meta

from reflector_opt.tolerance._analysis import SettingsTable, TargetsTable
from reflector_opt.tolerance._study import BATCH_SIZE
from reflector_opt.tolerance._tolerances import TolerancesTable
from reflector_opt.util import _schema as schema
from reflector_opt.util._limits import MAX_SIMULATED_UNITS, MAX_WORKERS

Units = Annotated[int, Meta(ge=1, le=MAX_SIMULATED_UNITS)]


class RunTable(schema.Table):
    """``[run]``: sizes of the study and of its execution."""

    samples: Annotated[Units, Meta(description="Monte Carlo samples")] = 500
    seed: Annotated[int, Meta(ge=0, le=2**63 - 1)] = 0
    oat_samples: Annotated[
        int, Meta(ge=0, le=MAX_SIMULATED_UNITS, description="per one-at-a-time run (0: none)")
    ] = 16
    sobol_samples: Annotated[
        int, Meta(ge=0, le=MAX_SIMULATED_UNITS, description="0 or a power of two")
    ] = 256
    batch_size: Annotated[Units, Meta(description="samples per batch")] = BATCH_SIZE
    workers: Annotated[int, Meta(ge=1, le=MAX_WORKERS, description="local processes")] = 2


class ToleranceDocument(schema.Table):
    """A tolerance config: lengths in mm, angles in degrees, voltages in volts."""

    tolerances: TolerancesTable = msgspec.field(default_factory=TolerancesTable)
    settings: SettingsTable = msgspec.field(default_factory=SettingsTable)
    targets: TargetsTable = msgspec.field(default_factory=TargetsTable)
    run: RunTable = msgspec.field(default_factory=RunTable)


def json_schema():
    """The JSON Schema of the tolerance config, published as ``docs/tolerance.schema.json``.

    Returns
    -------
    dict
    """
    return schema.json_schema(ToleranceDocument, "tolerance study config (TOML)")

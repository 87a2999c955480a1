"""The declared schema of the optimiser's TOML config (``reflector-opt optimise --config``).

:class:`OptimiseDocument` states every section and key with its type, unit, range and
default (the defaults are those of :class:`~reflector_opt.optimiser.Problem`,
:class:`~reflector_opt.optimiser.SearchBudget` and
:class:`~reflector_opt.optimiser._robust.RobustOptions`, read from them). What it cannot state
— a preset or material name, min below max, the bounds' variable names, a problem no design
can meet — is checked by the objects built from it
(:func:`reflector_opt.optimiser._config.parse_config`).
"""

from typing import Annotated

import msgspec
from msgspec import Meta

from reflector_opt.design import Workspace
from reflector_opt.design._conditions import Conditions
from reflector_opt.design._parts import CadTable
from reflector_opt.design._schema import AngleRange, MechanicsBlock, NoiseBlock
from reflector_opt.optimiser._drift_front import DEFAULT_DRIFT_FRACTIONS
from reflector_opt.optimiser._pareto import DEFAULT_MARGINS_MM
from reflector_opt.optimiser._problem import (
    ConstraintsTable,
    Distance,
    ObjectiveTable,
    Problem,
    SurfaceTable,
)
from reflector_opt.optimiser._robust import RobustTable
from reflector_opt.optimiser._search import SearchTable
from reflector_opt.util import _schema as schema
from reflector_opt.util._limits import MAX_ANGLE_DEG, MAX_LENGTH_MM

#: Most margins of a Pareto front (each costs one optimisation).
MAX_PARETO_POINTS = 100

Bound = Annotated[float, Meta(ge=-MAX_LENGTH_MM, le=MAX_LENGTH_MM)]

_PROBLEM = Problem()
_WORKSPACE = Workspace()


class SensorTable(schema.Table):
    """``[sensor]``: the sensor part."""

    model: Annotated[str, Meta(description="a sensor preset")] = _PROBLEM.sensor.name
    range_mm: (
        Annotated[
            list[Distance],
            Meta(min_length=2, max_length=2, description="usable distance [min, max], mm"),
        ]
        | None
    ) = None


class WorkspaceTable(schema.Table):
    """``[workspace]``: the poses a unit must sense."""

    pitch_deg: Annotated[AngleRange, Meta(description="pitch γ range, degrees")] = msgspec.field(
        default_factory=lambda: list(_WORKSPACE.pitch_deg)
    )
    roll_deg: Annotated[AngleRange, Meta(description="roll α range, degrees")] = msgspec.field(
        default_factory=lambda: list(_WORKSPACE.roll_deg)
    )
    step_deg: Annotated[
        float, Meta(gt=0, lt=2 * MAX_ANGLE_DEG, description="calibration grid step, degrees")
    ] = _WORKSPACE.step_deg


class ParetoTable(schema.Table):
    """``[pareto]``."""

    margins_mm: Annotated[
        list[Distance],
        Meta(min_length=1, max_length=MAX_PARETO_POINTS, description="distance margins, mm"),
    ] = msgspec.field(default_factory=lambda: list(DEFAULT_MARGINS_MM))
    drift_fractions: Annotated[
        list[Annotated[float, Meta(gt=0, lt=1)]],
        Meta(
            min_length=1,
            max_length=MAX_PARETO_POINTS,
            description="drift limits of the drift front, as fractions of the white-noise "
            "optimum's drift",
        ),
    ] = msgspec.field(default_factory=lambda: list(DEFAULT_DRIFT_FRACTIONS))


class OptimiseDocument(schema.Table):
    """An optimiser config: lengths in mm, angles in degrees, voltages in volts."""

    sensor: SensorTable = msgspec.field(default_factory=SensorTable)
    workspace: WorkspaceTable = msgspec.field(default_factory=WorkspaceTable)
    mechanics: MechanicsBlock = msgspec.field(default_factory=MechanicsBlock)
    noise: NoiseBlock = msgspec.field(default_factory=NoiseBlock)
    bounds: Annotated[
        dict[str, Annotated[list[Bound], Meta(min_length=2, max_length=2)]],
        Meta(description="design variable = [min, max] (min == max fixes it)"),
    ] = msgspec.field(default_factory=dict)
    objective: ObjectiveTable = msgspec.field(default_factory=ObjectiveTable)
    constraints: ConstraintsTable = msgspec.field(default_factory=ConstraintsTable)
    search: SearchTable = msgspec.field(default_factory=SearchTable)
    pareto: ParetoTable = msgspec.field(default_factory=ParetoTable)
    robust: RobustTable = msgspec.field(default_factory=RobustTable)
    cad: CadTable = msgspec.field(default_factory=CadTable)
    surface: SurfaceTable = msgspec.field(default_factory=SurfaceTable)
    conditions: Annotated[
        Conditions,
        Meta(
            description="operating conditions: optimise the worst-case total error in them "
            "(a config without this table optimises the white-noise resolution)"
        ),
    ] = msgspec.field(default_factory=Conditions)


def json_schema():
    """The JSON Schema of the optimiser config, published as ``docs/optimise.schema.json``.

    Returns
    -------
    dict
    """
    return schema.json_schema(OptimiseDocument, "optimiser config (TOML)")

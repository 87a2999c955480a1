"""The built-in design, resembling the paper's prototype unit."""

from __future__ import annotations

from reflector_opt.design.components import Reflector, SensorPlacement
from reflector_opt.design.design import Design, load_design

__all__ = ["as_design", "default_design"]


def as_design(design):
    """A design as the library calls take it: a :class:`Design`, its ``design.json``, or
    None for the built-in :func:`default_design`.

    Parameters
    ----------
    design : Design, str, pathlib.Path or None

    Returns
    -------
    Design
    """
    if design is None:
        return default_design()
    return design if isinstance(design, Design) else load_design(design)


def default_design():
    """The built-in design, resembling the paper's prototype unit.

    A 22 mm unit with the GE6 bearing (6 mm bore, 14 mm outer diameter), two NJL5901R-2
    sensors 90° apart at 10 mm from the rotation centre looking radially inwards, and a
    reflector sphere of radius 9 mm whose centre sits 1.4 mm below the rotation centre;
    the inner surface (7.5 mm) clears the bearing's outer ring. Workspace ±15° pitch and
    roll in 0.1° steps. The paper gives neither the radius nor the offset (assumed figures);
    the offset is the largest in 0.1 mm steps whose reflecting shell reaches the printable
    0.8 mm wall (0.813 mm at 1.4 mm; 0.751 mm at 1.5 mm, docs/cad.md).

    Returns
    -------
    Design
    """
    return Design(
        reflector=Reflector(),
        sensors=(
            SensorPlacement("S1", "NJL5901R-2", (10.0, 0.0, 0.0), (-1.0, 0.0, 0.0)),
            SensorPlacement("S2", "NJL5901R-2", (0.0, 10.0, 0.0), (0.0, -1.0, 0.0)),
        ),
    )

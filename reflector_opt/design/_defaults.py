"""The built-in design, resembling the paper's prototype unit."""

from dataclasses import replace

from reflector_opt.design._components import Reflector, SensorPlacement
from reflector_opt.design._design import Design, load_design


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


def default_design(like=None):
    """The built-in design, resembling the paper's prototype unit; or its geometry placed in
    the unit of ``like``, the design every improvement is measured against.

    A 22 mm unit with the GE6 bearing (6 mm bore, 14 mm outer diameter), two NJL5901R-2
    sensors 90° apart at 10 mm from the rotation centre looking radially inwards, and a
    reflector sphere of radius 9 mm whose centre sits 1.4 mm below the rotation centre;
    the inner surface (7.5 mm) clears the bearing's outer ring. Workspace ±15° pitch and
    roll in 0.1° steps. The paper gives neither the radius nor the offset (assumed figures);
    the offset is the largest in 0.1 mm steps whose reflecting shell reaches the printable
    0.8 mm wall (0.813 mm at 1.4 mm; 0.751 mm at 1.5 mm, docs/cad.md).

    Parameters
    ----------
    like : Design, optional
        A design whose unit the built-in geometry is placed in: its mechanics (envelope,
        bearing, wall), workspace, noise, sensor parts (each default sensor takes the part of
        the design's sensor at its place in the list, with the parts the design defines) and
        its reflector's reflectance and specular fraction; the sphere, the inner radius and
        the sensors' positions and axes stay the built-in ones. For a design in the paper's
        unit (the defaults of each) this is the built-in design itself. ``evaluate``,
        ``report`` and ``optimise`` compare with it (docs/optimiser.md).

    Returns
    -------
    Design
        Raises :class:`~reflector_opt.util._errors.InputError` where the built-in geometry is
        not a valid design in that unit (a sensor touching the sphere in its workspace).
    """
    design = Design(
        reflector=Reflector(),
        sensors=(
            SensorPlacement("S1", "NJL5901R-2", (10.0, 0.0, 0.0), (-1.0, 0.0, 0.0)),
            SensorPlacement("S2", "NJL5901R-2", (0.0, 10.0, 0.0), (0.0, -1.0, 0.0)),
        ),
    )
    if like is None:
        return design
    surface = {k: getattr(like.reflector, k) for k in ("reflectance", "specular_fraction")}
    return design.replace(
        reflector=replace(design.reflector, **surface),
        sensors=tuple(
            replace(s, model=t.model)
            for s, t in zip(design.sensors, like.sensors[: len(design.sensors)], strict=True)
        ),
        workspace=like.workspace,
        mechanics=like.mechanics,
        noise=like.noise,
        sensor_models=like.sensor_models,
    )

"""A calibration as a C99 header, as ``reflector-opt firmware`` writes it
(:mod:`reflector_opt.robot._firmware`)."""

from dataclasses import dataclass, replace
from pathlib import Path

from reflector_opt.util._declared import Options, option, takes
from reflector_opt.util._display import Printed


@dataclass(frozen=True, repr=False)
class FirmwareRun(Printed):
    """The header of a calibration (:func:`firmware`), its operations and its code size.

    Attributes
    ----------
    header : str
        The C99 header.
    units : list of str
        The units, in the functions' order.
    operations : dict
        ``mul``, ``add``, ``div`` per frame of every unit, float evaluation.
    bounds_deg : list of float
        Each unit's fixed-point error bound within its calibration's range, degrees.
    code_size : tuple or None
        The compiler as run and the bytes of the float and fixed-point code; None without one.
    files : tuple of pathlib.Path
        The header, once written.
    """

    header: str
    units: list
    operations: dict
    bounds_deg: list
    code_size: tuple | None
    files: tuple = ()

    def write(self, output):
        """Write the header, atomically; returns this run with ``files``."""
        from reflector_opt.util._fileio import write_text

        write_text(output, self.header)
        return replace(self, files=(Path(output),))

    def to_dict(self):
        """JSON-ready (``firmware --json``)."""
        compiler, sizes = self.code_size or (None, None)
        return {
            "units": self.units,
            "operations_per_frame": self.operations,
            "fixed_point_bound_deg": self.bounds_deg,
            "compiler": compiler,
            "code_bytes": sizes,
            "output": str(self.files[0]) if self.files else None,
        }

    def text(self):
        """The operations per frame, the fixed-point bound and the code size."""
        ops = ", ".join(f"{v} {k}" for k, v in self.operations.items())
        lines = [
            f"{len(self.units)} unit(s) in C99: {ops} per frame (float)",
            f"fixed point (u in Q3.28, angles in Q11.20): error ≤ {max(self.bounds_deg):.2g}°",
        ]
        if self.code_size is None:
            lines.append("code size: no C compiler found")
        else:
            compiler, sizes = self.code_size
            host = "" if "arm" in compiler else "; for this host: no arm-none-eabi-gcc"
            lines.append(
                f"code size ({compiler}{host}): float {sizes['float']} B, "
                f"fixed point {sizes['fixed']} B"
            )
        return "\n".join(lines)


class FirmwareOptions(Options):
    """The options of ``reflector-opt firmware``, declared once."""

    name: option(
        str, "prefix of the C names (a C identifier)", pattern=r"^[A-Za-z_][A-Za-z0-9_]*$"
    ) = "ro"


@takes(FirmwareOptions)
def firmware(coefficients, options=None):
    """A coefficients file of ``calibrate`` as a C99 header: ``reflector-opt firmware``.

    Parameters
    ----------
    coefficients : str or pathlib.Path
    options : FirmwareOptions
        As keyword arguments (below).

    Returns
    -------
    FirmwareRun

    Raises
    ------
    InputError
        A file that cannot be read, a physical model, a prefix that is not a C identifier.
    """
    from reflector_opt.robot._firmware import (
        code_size,
        firmware_header,
        fixed_point_bound,
        operations,
        unit_forms,
    )
    from reflector_opt.workflow._estimate import load_unit_calibrations

    calibrations = load_unit_calibrations(coefficients)
    header = firmware_header(calibrations, options.name)
    forms = unit_forms(calibrations)
    return FirmwareRun(
        header,
        [label for label, _, _ in forms],
        operations(calibrations),
        [fixed_point_bound(form, thermal) for _, form, thermal in forms],
        code_size(header, options.name),
    )

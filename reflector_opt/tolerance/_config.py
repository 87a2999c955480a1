"""TOML configuration of a tolerance study (``reflector-opt tolerance --config FILE.toml``).

Every section and key is optional; unknown ones are an error.

.. code-block:: toml

    [tolerances]                     # scale (and kind) of each tolerance, see Tolerances
    centre_offset_mm = 0.05          # a bare number keeps the default kind
    sensor_tilt_deg = { scale = 2.0, kind = "uniform" }
    multiplexed = true               # sensors driven in turn: no crosstalk

    [settings]                       # calibration_step_deg, n_validation, metrics_step_deg,
                                     # model, fit
    [targets]                        # window, rms_deg, max_deg
    [run]                            # samples, seed, oat_samples, sobol_samples, batch_size,
                                     # workers
"""

import dataclasses
from dataclasses import dataclass, field

import msgspec

from reflector_opt.tolerance._analysis import Settings, Targets
from reflector_opt.tolerance._schema import RunTable, ToleranceDocument
from reflector_opt.tolerance._sensitivity import check_rows
from reflector_opt.tolerance._study import BATCH_SIZE
from reflector_opt.tolerance._tolerances import Tolerances
from reflector_opt.util import _schema as schema
from reflector_opt.util._errors import in_section
from reflector_opt.util._fileio import read_config


@dataclass(frozen=True)
class RunOptions:
    """Sizes of a study and of its execution.

    Parameters
    ----------
    samples : int
        Monte Carlo samples.
    seed : int
    oat_samples : int
        Samples of each one-at-a-time run (0: none).
    sobol_samples : int
        Rows of each Sobol matrix: 0 (none) or a power of two.
    batch_size : int
        Samples per batch sent to a worker.
    workers : int
        Local worker processes (without ``--scheduler``).
    """

    samples: int = 500
    seed: int = 0
    oat_samples: int = 16
    sobol_samples: int = 256
    batch_size: int = BATCH_SIZE
    workers: int = 2

    def __post_init__(self):
        """Check every field against ``[run]``'s declaration
        (:class:`~reflector_opt.tolerance._schema.RunTable`), the one place its ranges are
        stated, and the Sobol rows (a power of two)."""
        schema.convert(dataclasses.asdict(self), RunTable, where="run")
        check_rows(self.sobol_samples, "run.sobol_samples")


@dataclass(frozen=True)
class ToleranceConfig:
    """Everything ``reflector-opt tolerance`` and ``sweep`` need besides the design."""

    tolerances: Tolerances = field(default_factory=Tolerances)
    settings: Settings = field(default_factory=Settings)
    targets: Targets = field(default_factory=Targets)
    run: RunOptions = field(default_factory=RunOptions)


def parse_tolerance_config(data):
    """Build a :class:`ToleranceConfig` from a parsed TOML document.

    The document is checked against :class:`~reflector_opt.tolerance._schema.ToleranceDocument`
    (types, ranges, unknown keys); the objects built from it check the rest.

    Parameters
    ----------
    data : dict
        As returned by :func:`tomllib.loads`.

    Returns
    -------
    ToleranceConfig
        Raises :class:`~reflector_opt.util._errors.InputError` naming the section and key.
    """
    document = schema.convert(data, ToleranceDocument, toml=True)
    parts = {"tolerances": Tolerances.from_table(document.tolerances)}
    for name, cls in (("settings", Settings), ("targets", Targets), ("run", RunOptions)):
        with in_section(name):
            parts[name] = cls(**msgspec.structs.asdict(getattr(document, name)))
    return ToleranceConfig(**parts)


def load_tolerance_config(path):
    """Read and check a tolerance config file.

    Parameters
    ----------
    path : str or pathlib.Path

    Returns
    -------
    ToleranceConfig
    """
    return read_config(path, parse_tolerance_config)

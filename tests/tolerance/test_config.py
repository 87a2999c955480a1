"""The tolerance study's configuration: bad settings and run options, the example as documented."""

import pytest

from reflector_opt.tolerance import (
    Settings,
    Spread,
    Targets,
)
from reflector_opt.tolerance._config import parse_tolerance_config
from reflector_opt.util._errors import InputError


def test_bad_settings_and_run_options():
    with pytest.raises(InputError, match=r"settings\.calibration_step_deg"):
        parse_tolerance_config({"settings": {"calibration_step_deg": 0}})
    with pytest.raises(InputError, match=r"run\.samples"):
        parse_tolerance_config({"run": {"samples": 0}})
    with pytest.raises(InputError, match=r"targets\.rms_deg"):
        parse_tolerance_config({"targets": {"rms_deg": -1}})
    with pytest.raises(InputError, match="unknown section"):
        parse_tolerance_config({"tolerance": {}})
    with pytest.raises(InputError, match="model"):
        Settings(model="eq7")
    # the key was lost: 'settings.unknown model 'eq7'; …', 'settings.poly0: the degree …'
    with pytest.raises(InputError, match=r"^settings\.model: unknown model 'eq7'; choose"):
        parse_tolerance_config({"settings": {"model": "eq7"}})
    with pytest.raises(InputError, match=r"^settings\.model: poly0: the degree must be"):
        parse_tolerance_config({"settings": {"model": "poly0"}})
    with pytest.raises(
        InputError, match=r"^fit: expected one of 'huber', 'lsq', 'minimax', got 'l1'$"
    ):
        Settings(fit="l1")


def test_example_config_reads_as_documented():
    from pathlib import Path

    from reflector_opt.tolerance._config import load_tolerance_config

    path = Path(__file__).resolve().parents[2] / "examples" / "tolerance.toml"
    config = load_tolerance_config(path)
    assert config.tolerances.sensor_tilt_deg == Spread(2.0, "uniform")
    assert config.tolerances.centre_offset_mm == Spread(0.05, "normal")
    assert config.tolerances.crosstalk_fraction == Spread(0.01, "uniform")
    assert config.settings == Settings()
    assert config.targets == Targets()
    assert (config.run.samples, config.run.sobol_samples) == (500, 256)

"""The CAD parameters of the printable parts (design.parts): their checks and their file."""

import pytest

from reflector_opt.design._parts import CadParameters, load_cad_parameters
from reflector_opt.util._errors import InputError


def test_cad_parameters_validation_and_toml(tmp_path):
    with pytest.raises(InputError, match=r"cad\.clearance_mm: must not be negative"):
        CadParameters(clearance_mm=-0.1)
    with pytest.raises(InputError, match=r"cad\.lid_thickness_mm: must be positive"):
        CadParameters(lid_thickness_mm=0.0)
    path = tmp_path / "cad.toml"
    path.write_text("[cad]\nclearance_mm = 0.3\ntendon_azimuth_deg = 40.0\n")
    params = load_cad_parameters(path)
    assert params.clearance_mm == 0.3 and params.tendon_azimuth_deg == 40.0
    path.write_text("clearence_mm = 0.3\n")
    with pytest.raises(InputError, match="unknown key"):
        load_cad_parameters(path)
    # a key of the [cad] table was named without it: 'clearance_mm: expected …'
    path.write_text("[cad]\nclearance_mm = -1\n")
    with pytest.raises(InputError, match=r"cad\.toml: cad\.clearance_mm: expected a number from 0"):
        load_cad_parameters(path)
    path.write_text("clearance_mm = -1\n")  # top-level keys are named as they stand
    with pytest.raises(InputError, match=r"cad\.toml: clearance_mm: expected a number from 0"):
        load_cad_parameters(path)

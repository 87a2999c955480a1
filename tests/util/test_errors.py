"""An input error is one line whatever the user's file holds."""

import pickle

import numpy as np
import pytest

from reflector_opt.calibration import Eq6
from reflector_opt.calibration._coefficients import model_from_dict, model_to_dict
from reflector_opt.util._errors import CollisionError, InputError


def test_control_characters_are_written_as_escapes():
    error = InputError("key 'a\nb\tc\x00' is unknown\r")
    assert str(error) == "key 'a\\nb\\tc\\x00' is unknown\\r"
    assert len(str(error).splitlines()) == 1
    assert str(CollisionError("x\ny")) == "x\\ny"
    assert str(pickle.loads(pickle.dumps(error))) == str(error)


def test_a_newline_in_a_coefficient_file_key_stays_on_one_line():
    # Found by the property test of the coefficient reader with more examples: the key of an
    # unknown model parameter reached the message raw.
    rng = np.random.default_rng(0)
    volts = rng.uniform(0.5, 2.5, (60, 2))
    document = model_to_dict(Eq6().fit(volts, np.column_stack([volts[:, 0], volts[:, 1]])))
    document["params"]["\n"] = 1
    with pytest.raises(InputError, match="unexpected keyword argument") as caught:
        model_from_dict(document)
    assert "\n" not in str(caught.value) and "'\\n'" in str(caught.value)


def test_in_section_names_the_section_once():
    """A key's message gets its section before it; one that names the section already is
    kept; other errors pass through."""
    from reflector_opt.util._errors import in_section

    with pytest.raises(InputError, match=r"^robust\.coverage: bad$"):
        with in_section("robust"):
            raise InputError("coverage: bad")
    with pytest.raises(InputError, match=r"^run\.workers: bad$"):
        with in_section("run"):
            raise InputError("run.workers: bad")
    with pytest.raises(KeyError):
        with in_section("run"):
            raise KeyError("workers")

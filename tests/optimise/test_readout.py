"""The read-out chosen for a design: the candidates by hand, the simplest within its worth."""

import math

import pytest

from reflector_opt.analysis._budget import detector_time_constants_s, error_budget
from reflector_opt.design._conditions import Conditions
from reflector_opt.design._defaults import default_design
from reflector_opt.model._settling import SETTLED_SHARE
from reflector_opt.optimiser import _readout as readout
from reflector_opt.optimiser._readout import READ_OUT_WORTH, ReadOut, choose_read_out


@pytest.fixture(scope="module")
def judged():
    design, stated = default_design(), Conditions()
    return design, stated, readout.read_out_candidates(design, stated)


def test_candidates_are_every_drive_each_compensated_or_not_at_a_settled_rate(judged):
    design, stated, candidates = judged
    keys = [(r.conditions.drive, r.conditions.temperature_compensated) for r in candidates]
    assert keys == [(d, c) for c in (False, True) for d in ("dc", "multiplexed", "modulated")]
    # dc keeps the stated rate; the switched drives the detectors' settling rate (to 0.1 %),
    # f = 1 / (tau ln 1000), rounded down to two figures, where it is below the stated rate
    tau = max(max(pair) for pair in detector_time_constants_s(design.models))
    settling = 1.0 / (tau * math.log(1.0 / SETTLED_SHARE))
    assert settling < stated.sample_rate_hz
    two_figures = math.floor(settling / 10 ** (math.floor(math.log10(settling)) - 1))
    for r in candidates:
        expected = stated.sample_rate_hz if r.conditions.drive == "dc" else two_figures * 10.0
        assert r.conditions.sample_rate_hz == pytest.approx(expected, rel=1e-12)
        assert r.conditions.sample_rate_hz <= settling or r.conditions.drive == "dc"
    # every figure is the budget's in that read-out, the frame rate every sensor read once
    for r in candidates:
        budget = error_budget(design, r.conditions)
        assert r.worst_case_deg == pytest.approx(budget.worst_case_deg, rel=1e-12)
        reads = 2 if r.conditions.drive == "modulated" else 1
        assert r.frame_rate_hz == pytest.approx(
            r.conditions.sample_rate_hz / (reads * len(design.sensors)), rel=1e-12
        )
    # what each changes is physics the budget knows: compensation lowers the temperature term
    plain, compensated = candidates[0], candidates[3]
    assert compensated.worst_case_deg < plain.worst_case_deg


def _fake(worst):
    return [ReadOut(Conditions(), w, w, 100.0) for w in worst]


@pytest.mark.parametrize(
    ("worst", "index"),
    [
        ([1.0, 0.99, 0.98, 0.97, 0.96, 0.955], 0),  # the best within 5 % of the plainest
        ([1.0, 0.99, 0.90, 0.97, 0.96, 0.89], 2),  # modulated within 5 % of the compensated
        ([1.0, 0.99, 0.98, 0.97, 0.96, 0.50], 5),  # only the costliest is worth it
    ],
)
def test_the_simplest_within_its_worth_of_the_best_is_chosen(monkeypatch, worst, index):
    fake = _fake(worst)
    monkeypatch.setattr(readout, "read_out_candidates", lambda *args, **kwargs: fake)
    chosen, candidates = choose_read_out(None, None)
    assert chosen is fake[index] and candidates is fake
    assert chosen.worst_case_deg <= min(worst) * (1 + READ_OUT_WORTH)
    assert all(w > min(worst) * (1 + READ_OUT_WORTH) for w in worst[:index])

import json

import pytest

from softgym.design.controller import CONTROLLER_BOUNDS, Controller
from softgym.exceptions import InvalidDesignError, InvalidParameterError


def test_controller_defaults_and_bounds():
    c = Controller()
    assert (c.temp_amplitude, c.period, c.muscle_cte) == (14.0, 0.25, 0.01)
    assert c.frequency == 4.0
    assert c.temperature(0.0625) == pytest.approx(14.0)
    assert CONTROLLER_BOUNDS["period"][:2] == (0.01, 0.75)
    for name, (lo, hi, _) in CONTROLLER_BOUNDS.items():
        Controller(**{name: lo})
        Controller(**{name: hi})
        with pytest.raises(InvalidParameterError, match=name):
            Controller(**{name: hi * 1.01})
        with pytest.raises(InvalidParameterError, match=name):
            Controller(**{name: lo * 0.99})
    with pytest.raises(InvalidParameterError, match="must be a number"):
        Controller(period="fast")


def test_controller_clipped_and_clip():
    c = Controller.clipped(temp_amplitude=25.0, period=0.001, muscle_cte=0.02)
    assert (c.temp_amplitude, c.period, c.muscle_cte) == (20.0, 0.01, 0.02)
    d = c.clip(period=0.9, muscle_cte=-1.0)
    assert (d.temp_amplitude, d.period, d.muscle_cte) == (20.0, 0.75, 0.001)
    with pytest.raises(InvalidParameterError, match="finite"):
        Controller.clipped(temp_amplitude=float("nan"))
    with pytest.raises(InvalidParameterError, match="unknown"):
        c.clip(phase=1.0)


def test_controller_dict_roundtrip():
    c = Controller(7.5, 0.1, 0.033)
    assert Controller.from_dict(json.loads(json.dumps(c.to_dict()))) == c
    with pytest.raises(InvalidDesignError, match="unknown controller field"):
        Controller.from_dict({"period": 0.2, "gain": 1})

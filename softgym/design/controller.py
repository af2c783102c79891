"""The seed's open-loop controller: a global sinusoidal temperature signal.

Every muscle voxel sees ``T(t) = dT sin(2 pi t / period)``; a voxel of CTE
``c`` is driven by ``c * T(t)``. Materials 3 (Active_+) and 4 (Active_-) get
``cte = +muscle_cte`` and ``-muscle_cte``, so the two muscle kinds work in
counter-phase (docs/PHYSICS.md).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, replace
from typing import Any, ClassVar

from softgym.exceptions import InvalidDesignError, InvalidParameterError
from softgym.validate import number

__all__ = ["CONTROLLER_BOUNDS", "Controller"]

#: The seed's controller-evolution bounds (the seed study): name -> (low, high, unit).
CONTROLLER_BOUNDS: dict[str, tuple[float, float, str]] = {
    "temp_amplitude": (1.0, 20.0, "degC"),
    "period": (0.01, 0.75, "s"),
    "muscle_cte": (0.001, 0.04, "1/degC"),
}


@dataclass(frozen=True)
class Controller:
    """Amplitude, period and muscle CTE of the global sinusoidal actuation.

    Defaults are the seed's (evosoro's) values. Construction outside
    :data:`CONTROLLER_BOUNDS` raises :class:`~softgym.exceptions.InvalidParameterError`;
    mutation code should build children with :meth:`clipped`.

    Parameters
    ----------
    temp_amplitude : float
        Temperature amplitude dT (°C), in [1, 20]. Default 14.
    period : float
        Period of the signal (s), in [0.01, 0.75]. Default 0.25 (4 Hz).
    muscle_cte : float
        CTE magnitude (1/°C) given to materials 3 (+) and 4 (-), in [0.001, 0.04].
        Default 0.01.
    """

    temp_amplitude: float = 14.0
    period: float = 0.25
    muscle_cte: float = 0.01

    #: Ids of the materials whose CTE the controller sets (+muscle_cte, -muscle_cte).
    MUSCLE_PAIR: ClassVar[tuple[int, int]] = (3, 4)

    def __post_init__(self) -> None:
        for name, (lo, hi, unit) in CONTROLLER_BOUNDS.items():
            value = number(f"controller {name}", getattr(self, name), finite=False)
            if not (math.isfinite(value) and lo <= value <= hi):
                raise InvalidParameterError(
                    f"controller {name} = {value} {unit} is outside the seed's bounds [{lo}, {hi}]"
                )
            object.__setattr__(self, name, value)

    @property
    def frequency(self) -> float:
        """Frequency (Hz) of the signal."""
        return 1.0 / self.period

    @classmethod
    def clipped(
        cls, temp_amplitude: float = 14.0, period: float = 0.25, muscle_cte: float = 0.01
    ) -> Controller:
        """Build a controller with each value clipped into :data:`CONTROLLER_BOUNDS`.

        Non-finite values still raise :class:`InvalidParameterError`.
        """
        values = {"temp_amplitude": temp_amplitude, "period": period, "muscle_cte": muscle_cte}
        out = {}
        for name, raw in values.items():
            lo, hi, _ = CONTROLLER_BOUNDS[name]
            v = number(f"controller {name}", raw, finite=False)
            if not math.isfinite(v):
                raise InvalidParameterError(f"controller {name} must be finite, got {v}")
            out[name] = min(max(v, lo), hi)
        return cls(**out)

    def clip(self, **changes: float) -> Controller:
        """Return a copy with ``changes`` applied and every value clipped into bounds."""
        values = {
            "temp_amplitude": self.temp_amplitude,
            "period": self.period,
            "muscle_cte": self.muscle_cte,
        }
        unknown = set(changes) - set(values)
        if unknown:
            raise InvalidParameterError(f"unknown controller parameter(s) {sorted(unknown)}")
        values.update(changes)
        return Controller.clipped(**values)

    def replace(self, **changes: float) -> Controller:
        """Return a copy with some values changed (validated, not clipped)."""
        return replace(self, **changes)

    def temperature(self, t: float) -> float:
        """Temperature command ``dT sin(2 pi t / period)`` (°C) at time ``t`` (s)."""
        return self.temp_amplitude * math.sin(2.0 * math.pi * t / self.period)

    def to_dict(self) -> dict[str, float]:
        """JSON-ready dict."""
        return {
            "temp_amplitude": self.temp_amplitude,
            "period": self.period,
            "muscle_cte": self.muscle_cte,
        }

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Controller:
        """Inverse of :meth:`to_dict`; unknown keys raise :class:`InvalidDesignError`."""
        if not isinstance(data, Mapping):
            raise InvalidDesignError(f"a controller must be an object, got {type(data).__name__}")
        unknown = set(data) - set(CONTROLLER_BOUNDS)
        if unknown:
            raise InvalidDesignError(f"unknown controller field(s) {sorted(map(str, unknown))}")
        return cls(**data)

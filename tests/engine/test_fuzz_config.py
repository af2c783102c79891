"""Hypothesis: every numeric field of SimConfig and Body, physical extremes included
(issue 31), is accepted with a usable time step or refused with a typed error."""

import math

import numpy as np
from fuzzing import FUZZ, outcome
from hypothesis import given
from hypothesis import strategies as st

from softgym.engine import Body, SimConfig, time_step

EXTREMES = (
    st.sampled_from([0.0, -0.0, 1e-300, 5e-324, 1e-30, 1e30, 1e300, -1e300, float("nan"),
                     float("inf"), True, "9.81", None, [1.0], 1j])  # fmt: skip
    | st.floats(1e-300, 1e300)
    | st.floats(-10.0, 10.0)
    | st.integers(-(2**70), 2**70)
)
CONFIG_FIELDS = ["voxel_size", "dt_frac", "gravity", "bond_damping", "collision_damping",
                 "global_damping", "init_time", "min_scale", "max_strain", "trace_interval",
                 "friction", "incline", "fluid_drag"]  # fmt: skip
BODY_FIELDS = ["youngs_modulus", "density", "poisson", "cte", "mu_static", "mu_kinetic"]


@FUZZ
@given(st.dictionaries(st.sampled_from(CONFIG_FIELDS), EXTREMES, max_size=3))
def test_configs_are_usable_or_refused(changes):
    if outcome("engine: SimConfig(**fields)", SimConfig, **changes) != "valid":
        return
    cfg = SimConfig(**changes)
    for name in changes:
        v = getattr(cfg, name)
        assert not isinstance(v, (str, bool)) and math.isfinite(float(v)), name
    dt = time_step(Body.uniform(np.ones((2, 1, 1))), cfg)
    assert math.isfinite(dt) and dt > 0


@FUZZ
@given(st.sampled_from(BODY_FIELDS), EXTREMES)
def test_bodies_are_usable_or_refused(field, value):
    kw = {field: value}
    if outcome("engine: Body.uniform(**fields)", Body.uniform, np.ones((2, 1, 1)), **kw) != "valid":
        return
    dt = time_step(Body.uniform(np.ones((2, 1, 1)), **kw))
    assert math.isfinite(dt) and dt > 0

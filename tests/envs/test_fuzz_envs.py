"""Hostile env arguments and actions: a working env and step, or a SoftGymError, nothing else.

Hypothesis properties over the keyword arguments of :class:`SoftWalkerEnv` and
:class:`SoftWalkerVectorEnv` (each one valid, out of range, or of another type) and over
the actions given to ``step`` (dtypes, shapes, values). An env that builds is reset and
stepped once; a refused action leaves the state untouched. ``fuzzing.OUTCOMES`` counts what each
property saw (used for the issue's tally). ``gym.make``'s own ``max_episode_steps`` is
Gymnasium's (its TimeLimit) and is not fuzzed here.
"""

import numpy as np
import pytest
from fuzzing import FUZZ, FUZZ_EXAMPLES  # tests/fuzzing.py
from fuzzing import outcome_and_result as outcome
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from softgym.design import RobotDesign, default_walker
from softgym.engine import SimConfig
from softgym.envs import SoftWalkerEnv, SoftWalkerVectorEnv
from softgym.terrain import Terrain

pytestmark = pytest.mark.filterwarnings("ignore:.*ends episodes after:UserWarning")

# building an env that works means settling it (about 0.1 s): fewer of those by default
FUZZ_KWARGS = settings(FUZZ, max_examples=max(1, FUZZ_EXAMPLES * 2 // 3))


JUNK = (
    st.none()
    | st.booleans()
    | st.integers()
    | st.sampled_from([0, -1, 10**30, 2**63])
    | st.integers(4400, 5000).map(lambda k: (-1) ** k * 10**k)  # too long for repr()
    | st.floats(allow_nan=True, allow_infinity=True)
    | st.complex_numbers(max_magnitude=10)
    | st.text(max_size=8)
    | st.binary(max_size=4)
    | st.lists(st.integers(-3, 12) | st.floats(0, 10), max_size=4)
    | st.dictionaries(st.text(max_size=3), st.integers(), max_size=2)
    | st.builds(np.array, st.lists(st.integers(-2, 8), max_size=3))
    | st.builds(np.bool_, st.booleans())
)
SMALL = RobotDesign(np.ones((2, 2, 2), dtype=np.int8))


# per argument: valid values and near misses (out of range, wrong spelling); any argument may
# also be replaced by JUNK (see env_kwargs)
KWARGS = {
    "design": st.sampled_from([None, "default", "small", "/nonexistent/design.json", "/", "."]),
    "task": st.sampled_from(["flat", "wall", "stairs", "fence", "lava", "FLAT"]),
    "episode_seconds": st.none() | st.floats(0.01, 1.0) | st.integers(1, 3),
    "control_dt": st.floats(0.005, 0.5) | st.sampled_from([1e-300, 1e300, 10.0, 10.5]),
    "actuation": st.sampled_from([None, "seed", "symmetric", "SEED"]),
    "self_collision": st.none() | st.booleans() | st.builds(np.bool_, st.booleans()),
    "grid_shape": (
        st.tuples(*[st.integers(5, 8)] * 3)
        | st.lists(st.integers(-2, 12), min_size=2, max_size=4)
        | st.tuples(st.integers(6, 7), st.floats(5, 8), st.integers(6, 7))
        | st.builds(np.array, st.lists(st.integers(6, 8), min_size=3, max_size=3))
    ),
    "sim_config": st.sampled_from([None, "default", "double"]),
    "terrain": st.sampled_from([None, "flat", "fence"]),
    "render_mode": st.sampled_from([None, "rgb_array", "human"]),
    "width": st.integers(1, 64) | st.integers(-5, 5) | st.integers(4090, 4100),
    "height": st.integers(1, 64),
    # (a valid 1024 is left out: the engine then starts 1024 OpenMP threads, even for 1 robot)
    "n_threads": st.none() | st.integers(-1, 4) | st.integers(1025, 1030),
    "max_episode_steps": st.none() | st.integers(-2, 50) | st.integers(10**6, 10**6 + 1),
    "drive": st.sampled_from(["action", "controller", "ACTION"]),
}


@st.composite
def env_kwargs(draw, table):
    """Some of ``table``'s arguments, valid or near misses, then 0-2 of them made junk."""
    kwargs = draw(st.fixed_dictionaries({}, optional=table))
    for key in draw(st.lists(st.sampled_from(sorted(table)), max_size=2, unique=True)):
        kwargs[key] = draw(JUNK)
    return kwargs


OBJECTS = {
    ("design", "default"): default_walker(),
    ("design", "small"): SMALL,
    ("sim_config", "default"): SimConfig(),
    ("sim_config", "double"): SimConfig(link_precision="double"),
    ("terrain", "flat"): Terrain.flat(),
    ("terrain", "fence"): Terrain.fence(),
}


def _objects(kwargs):
    # named stand-ins for objects (Hypothesis shows their names in a failing example)
    out = {}
    for k, v in kwargs.items():
        try:
            out[k] = OBJECTS.get((k, v), v)
        except TypeError:  # an unhashable value is itself the input
            out[k] = v
    return out


def _check_env_works(env):
    obs, info = env.reset(seed=0)
    n = env.action_space.shape
    obs, reward, terminated, truncated, info = env.step(np.zeros(n, dtype=np.float32))
    assert env.observation_space.contains(obs), "observation outside its space"
    assert np.all(np.isfinite(reward))
    if env.render_mode == "rgb_array":
        frames = env.render()
        for frame in frames if isinstance(frames, tuple) else [frames]:
            assert frame.shape == (env.height, env.width, 3) and frame.dtype == np.uint8
    env.close()


@FUZZ_KWARGS
@given(env_kwargs(KWARGS))
def test_env_kwargs_give_a_working_env_or_a_typed_error(kwargs):
    label, env = outcome("env: SoftWalkerEnv(**kwargs)", SoftWalkerEnv, **_objects(kwargs))
    if label == "valid":
        _check_env_works(env)


VECTOR_KWARGS = {
    "num_envs": st.integers(-1, 3) | st.sampled_from([65537, 10**30]),  # (65536 is slow to build)
    "n_threads": st.just(1),
    "designs": st.lists(st.sampled_from(["default", "small", "/nonexistent.json"]), max_size=3),
    "autoreset_mode": st.sampled_from(["next_step", "SAME_STEP", "Disabled", 0, 1, 2]),
    **{k: KWARGS[k] for k in ("design", "grid_shape", "max_episode_steps", "self_collision")},
    "episode_seconds": st.floats(0.01, 0.3),
    "render_mode": KWARGS["render_mode"],
    "width": st.integers(-5, 64),
    "height": KWARGS["height"],
}


def _vector(kwargs):
    kwargs = _objects(kwargs)
    designs = kwargs.get("designs")
    if isinstance(designs, list):
        kwargs["designs"] = [OBJECTS.get(("design", d), d) for d in designs]
    return SoftWalkerVectorEnv(**kwargs)


@FUZZ_KWARGS
@given(env_kwargs(VECTOR_KWARGS))
def test_vector_env_kwargs_give_a_working_env_or_a_typed_error(kwargs):
    label, venv = outcome("vector env: SoftWalkerVectorEnv(**kwargs)", _vector, kwargs)
    if label == "valid":
        _check_env_works(venv)


# ------------------------------------------------------------------ actions

DTYPES = st.sampled_from(
    [np.float64, np.float32, np.float16, np.int8, np.int64, np.uint8, np.uint64, np.bool_]
    + [np.complex128, np.longdouble, "U3", "S2", "M8[s]", "m8[s]", object]
)


def _shapes(want):
    n = int(np.prod(want))
    near = [want, (n,), (n - 1,), (n + 1,), (1, *want), (), (6, 6, 6), (2, n // 2), (n, 1)]
    return st.sampled_from(near) | hnp.array_shapes(max_dims=3, max_side=8)


def _filled(dtype, shape, fill):
    a = np.full(shape, fill)
    try:
        with np.errstate(invalid="ignore", over="ignore"):
            return a.astype(dtype)
    except (TypeError, ValueError, OverflowError):  # e.g. NaN as a date: keep the floats
        return a


def _real(want, seed, dtype, scale, special, as_list):
    # values drawn from a seed: a 432-entry action costs Hypothesis one draw, not 432
    rng = np.random.default_rng(seed)
    a = rng.uniform(-scale, scale, want)
    if special is not None:
        a.flat[rng.integers(a.size)] = special
    with np.errstate(invalid="ignore", over="ignore"):  # 1e308 as float32 is inf: refused
        if as_list:
            return a.round().astype(int).tolist() if dtype == "int" else a.tolist()
        return a.astype(np.float32 if dtype == "float32" else np.float64)


def actions(want):
    arrays = st.builds(
        _filled,
        DTYPES,
        _shapes(want),
        st.floats(allow_nan=True, allow_infinity=True) | st.integers(-3, 3),
    )
    real = st.builds(
        _real,
        st.just(want),
        st.integers(0, 2**32 - 1),
        st.sampled_from(["float64", "float32", "int"]),
        st.sampled_from([0.5, 1.0, 3.0, 1e300]),
        st.sampled_from([None, None, None, None, np.nan, np.inf, -np.inf, 1e308]),
        st.booleans(),
    )
    # half the actions are real arrays or lists of the right shape (most of them valid)
    return st.sampled_from([real, real, arrays, JUNK]).flatmap(lambda strategy: strategy)


class _Env:
    """One env per kind, built and reset once; the action properties reuse it."""

    single: SoftWalkerEnv | None = None
    vector: SoftWalkerVectorEnv | None = None


def _stepped(env, action):
    before = env.sim.get_state()
    label, result = outcome(f"action: {type(env).__name__}.step", env.step, action)
    if label != "valid":
        after = env.sim.get_state()
        assert all(np.array_equal(before[k], after[k]) for k in before), "state changed"
        return
    obs, reward, terminated, truncated, _ = result
    assert env.observation_space.contains(obs)
    assert np.all(np.isfinite(reward))
    if np.any(terminated) or np.any(truncated):
        env.reset(seed=0)


@FUZZ
@given(actions((216,)))
def test_single_env_actions_step_or_raise_a_typed_error(action):
    if _Env.single is None:
        _Env.single = SoftWalkerEnv(episode_seconds=4.0)
        _Env.single.reset(seed=0)
    _stepped(_Env.single, action)


@FUZZ
@given(actions((2, 216)))
def test_vector_env_actions_step_or_raise_a_typed_error(action):
    if _Env.vector is None:
        _Env.vector = SoftWalkerVectorEnv(2, episode_seconds=4.0, max_episode_steps=80, n_threads=1)
        _Env.vector.reset(seed=0)
    _stepped(_Env.vector, action)

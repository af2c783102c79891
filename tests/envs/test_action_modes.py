"""How actions drive the muscles: contraction levels (the default) or the seed's temperatures."""

import gymnasium as gym
import numpy as np
import pytest

import softgym  # noqa: F401  (registers the ids)
from softgym.design import default_walker
from softgym.envs import SoftWalkerEnv
from softgym.exceptions import InvalidParameterError

N = 216


def _signs():
    d = default_walker()  # fills its 6x6x6 grid: cell c is voxel c
    return np.sign(d.material_table()["cte"][d.grid]).reshape(-1)


def _scales(env):
    base = env.unwrapped
    s = np.full(N, np.nan)
    s[np.ravel_multi_index(tuple(base.sim.grid_index(0).T), base.grid_shape)] = base.sim.scales(0)
    return s / base.sim.config.voxel_size


def _step(env, value):
    env.step(np.full(N, value, dtype=np.float32))
    return _scales(env)


@pytest.fixture
def full():
    d = default_walker()
    return 1.0 - abs(d.controller.muscle_cte) * d.controller.temp_amplitude  # fully contracted


def test_defaults_follow_the_actuation_law():
    assert gym.make("SoftWalker-Flat-v0").unwrapped.action_mode == "contraction"
    assert gym.make("SoftWalker-Flat-v0", actuation="symmetric").unwrapped.action_mode == "temperature"
    venv = gym.make_vec("SoftWalker-Flat-v0", num_envs=2, action_mode="temperature")
    assert venv.action_mode == "temperature"


@pytest.mark.parametrize("bad", ["level", "", 1, True])
def test_an_unknown_action_mode_is_refused(bad):
    with pytest.raises(InvalidParameterError, match=r"action_mode must be None or one of \['contraction', 'temperature'\]"):
        SoftWalkerEnv(action_mode=bad, episode_seconds=0.1)


def test_contraction_actions_set_every_muscle_and_relax_it(full):
    env = gym.make("SoftWalker-Flat-v0", episode_seconds=1.0)
    env.reset(seed=0)
    muscle = env.unwrapped.muscle_mask
    plus, minus = _signs() > 0, _signs() < 0
    # -1: the positive-CTE muscles fully contracted, the negative ones at rest; +1 the reverse
    s = _step(env, -1.0)
    np.testing.assert_allclose(s[plus], full)
    np.testing.assert_allclose(s[minus], 1.0)
    s = _step(env, 1.0)  # no hold: the contracted muscles relax at once
    np.testing.assert_allclose(s[plus], 1.0)
    np.testing.assert_allclose(s[minus], full)
    np.testing.assert_allclose(_step(env, 0.0)[muscle], 0.5 * (1.0 + full))  # both half way
    s = _step(env, 0.5)
    np.testing.assert_allclose(s[plus], 1.0 - 0.25 * (1.0 - full))
    np.testing.assert_allclose(s[minus], 1.0 - 0.75 * (1.0 - full))
    assert (_scales(env)[~muscle] == 1.0).all()  # passive voxels keep their size


def test_temperature_actions_hold_a_contracted_muscle_under_the_seeds_law(full):
    env = gym.make("SoftWalker-Flat-v0", episode_seconds=1.0, action_mode="temperature")
    env.reset(seed=0)
    plus = _signs() > 0
    minus = _signs() < 0
    s = _step(env, -1.0)  # contracts the positive-CTE muscles only
    np.testing.assert_allclose(s[plus], full)
    np.testing.assert_allclose(s[minus], 1.0)
    s = _step(env, 1.0)  # would expand them: they keep their size (the seed's rule)
    np.testing.assert_allclose(s[plus], full)
    np.testing.assert_allclose(s[minus], full)


def test_action_from_temperatures_gives_the_seeds_sizes_without_its_hold(full):
    env = gym.make("SoftWalker-Flat-v0", episode_seconds=1.0)
    env.reset(seed=0)
    base = env.unwrapped
    plus, minus = _signs() > 0, _signs() < 0
    for f in (-1.0, -0.3, 0.6):
        a = base.action_from_temperatures(np.full(N, f))
        assert a.dtype == np.float32 and a.shape == (N,)
        env.step(a)
        s = _scales(env)
        # the muscles the temperature contracts get the seed's size, the others rest
        np.testing.assert_allclose(s[plus], 1.0 - (1.0 - full) * max(0.0, -f))
        np.testing.assert_allclose(s[minus], 1.0 - (1.0 - full) * max(0.0, f))
    temp = gym.make("SoftWalker-Flat-v0", action_mode="temperature").unwrapped
    f = np.linspace(-1, 1, N)
    np.testing.assert_array_equal(temp.action_from_temperatures(f), f.astype(np.float32))


def test_the_vector_env_maps_actions_as_the_single_env():
    rng = np.random.default_rng(3)
    actions = rng.uniform(-1, 1, (3, 2, N)).astype(np.float32)
    venv = gym.make_vec("SoftWalker-Flat-v0", num_envs=2, episode_seconds=0.5, n_threads=1)
    venv.reset(seed=0)
    for a in actions:
        vobs, *_ = venv.step(a)
    for r in range(2):
        env = gym.make("SoftWalker-Flat-v0", episode_seconds=0.5)
        env.reset(seed=0)
        for a in actions:
            obs, *_ = env.step(a[r])
        np.testing.assert_array_equal(obs, vobs[r])
    f = rng.uniform(-1, 1, (2, N))
    np.testing.assert_array_equal(
        venv.action_from_temperatures(f), np.stack([env.unwrapped.action_from_temperatures(x) for x in f])
    )


@pytest.mark.parametrize("bad", [np.zeros(1), np.zeros(N + 1), np.zeros((2, N)), np.full(N, 2.0),
                                 np.full(N, np.nan), "x"])  # fmt: skip
def test_action_from_temperatures_of_the_wrong_length_is_an_invalid_action_error(bad):
    # issue 61, item 11: a length-1 vector was broadcast to every cell; N + 1 a numpy ValueError
    from softgym.envs.vector import SoftWalkerVectorEnv
    from softgym.exceptions import InvalidActionError

    env = gym.make("SoftWalker-Flat-v0").unwrapped
    with pytest.raises(InvalidActionError, match="temperature fractions"):
        env.action_from_temperatures(bad)
    venv = SoftWalkerVectorEnv(num_envs=2)
    with pytest.raises(InvalidActionError, match="temperature fractions"):
        venv.action_from_temperatures(np.stack([bad] * 2) if np.ndim(bad) == 1 else np.zeros(N))

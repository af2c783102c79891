"""Registration, Gymnasium's env checker and the spaces of the SoftWalker ids."""

import warnings

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import softgym
from softgym.design import RobotDesign, default_walker
from softgym.envs import ENV_IDS, SoftWalkerEnv, SoftWalkerVectorEnv

IDS = sorted(ENV_IDS)
SENSING_IDS = sorted(softgym.envs.SENSING_ENV_IDS)


def small_design() -> RobotDesign:
    grid = np.zeros((4, 4, 4), dtype=np.int8)
    grid[:2] = 3
    grid[2:] = 4
    grid[:, :, 3] = 2
    return RobotDesign(grid)


def test_import_softgym_registers_every_id():
    assert "envs" in softgym.__all__
    assert len(SENSING_IDS) == len(IDS)
    for env_id in IDS + SENSING_IDS:
        spec = gym.spec(env_id)
        assert isinstance(spec.entry_point, str) and spec.entry_point.startswith("softgym.envs")
        assert spec.vector_entry_point == "softgym.envs.vector:SoftWalkerVectorEnv"
        assert spec.max_episode_steps is None  # the episode is set in seconds, not steps


@pytest.mark.parametrize("env_id", IDS + SENSING_IDS)
def test_check_env_passes_without_warnings(env_id):
    env = gym.make(env_id)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(env.unwrapped)
    env.close()


@pytest.mark.parametrize("precision", [None, "double"])
def test_both_link_precisions_pass_the_checker_and_repeat(precision):
    # the default (single-precision links) and SimConfig(link_precision="double")
    # through gym.make: Gymnasium's checker passes and a seeded episode repeats bit for
    # bit; the two precisions give different numbers
    from softgym.engine import SimConfig

    cfg = SimConfig(link_precision=precision)

    def rollout(c):
        env = gym.make("SoftWalker-Flat-v0", sim_config=c, episode_seconds=1.2)
        obs, _ = env.reset(seed=3)
        env.action_space.seed(3)
        out = [obs]
        for _ in range(6):
            out.append(env.step(env.action_space.sample())[0])
        env.close()
        return np.array(out)

    env = gym.make("SoftWalker-Flat-v0", sim_config=cfg)
    want = "double" if precision == "double" else "single"
    assert env.unwrapped.sim.config.effective_link_precision == want
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(env.unwrapped)
    env.close()
    first = rollout(cfg)
    assert np.array_equal(first, rollout(cfg))
    other = SimConfig(link_precision="single" if precision == "double" else "double")
    assert not np.array_equal(first, rollout(other))


def test_make_without_arguments_gives_the_default_walker():
    env = gym.make("SoftWalker-Flat-v0")
    base = env.unwrapped
    assert isinstance(base, SoftWalkerEnv)
    assert base.design == default_walker()
    assert base.max_steps == 80 and base.control_dt == 0.05
    assert base.action_mode == "contraction" and base.sim.config.actuation == "seed"
    assert env.action_space.shape == (216,) and env.observation_space.shape == (1301,)
    assert env.action_space.dtype == np.float32 and env.observation_space.dtype == np.float32
    env.close()


def test_close_twice_is_harmless():
    env = gym.make("SoftWalker-Wall-v0", render_mode="rgb_array", episode_seconds=0.2)
    env.reset(seed=0)
    env.render()
    env.close()
    env.close()
    venv = gym.make_vec("SoftWalker-Wall-v0", num_envs=2, episode_seconds=0.2)
    venv.close()
    venv.close()


def test_spaces_depend_on_the_grid_not_the_body(tmp_path):
    path = tmp_path / "small.json"
    small_design().save(path)
    a = gym.make("SoftWalker-Flat-v0")
    b = gym.make("SoftWalker-Flat-v0", design=str(path))
    assert b.unwrapped.design == small_design()
    assert a.observation_space == b.observation_space
    assert a.action_space == b.action_space
    obs, info = b.reset(seed=0)
    assert obs in b.observation_space
    # cells outside the 4x4x4 body are empty: zero features, no muscle
    cells = obs[: 6 * 216].reshape(6, 6, 6, 6)
    assert not cells[4:].any() and not cells[:, 4:].any() and not cells[:, :, 4:].any()
    assert info["muscle_mask"].reshape(6, 6, 6)[:4, :4, :3].all()
    assert not info["muscle_mask"].reshape(6, 6, 6)[:, :, 3:].any()
    c = gym.make("SoftWalker-Flat-v0", grid_shape=(4, 4, 4), design=small_design())
    assert c.action_space.shape == (64,) and c.observation_space.shape == (6 * 64 + 5,)


def test_make_vec_uses_the_batched_vector_env():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        venv = gym.make_vec("SoftWalker-Stairs-v0", num_envs=2, episode_seconds=0.2)
    assert isinstance(venv, SoftWalkerVectorEnv)
    assert venv.sim.n_robots == 2
    assert venv.single_action_space == gym.make("SoftWalker-Stairs-v0").action_space
    assert venv.action_space.shape == (2, 216)
    assert venv.observation_space.shape == (2, 1301)
    venv.close()


def test_sensing_ids_are_check_env_clean_and_see_their_task():
    from gymnasium.utils.env_checker import check_env

    from softgym.envs import SENSING_ENV_IDS, env_id
    from softgym.tasks import get_task
    from softgym.tasks.sensing import sensing_layout

    assert env_id("push", sensing=True) == "SoftWalker-Push-Sensing-v0" in SENSING_ENV_IDS
    for name in ("push", "gap", "turn"):
        env = gym.make(env_id(name, sensing=True))
        check_env(env.unwrapped, skip_render_check=True)
        size = sensing_layout(get_task(name), (6, 6, 6)).size
        assert env.observation_space.shape == (size,)
        assert gym.make(env_id(name)).observation_space.shape == (6 * 216 + 5,)  # v0 stays blind
    vec = gym.make_vec("SoftWalker-Push-Sensing-v0", num_envs=2, vectorization_mode="vector_entry_point")
    obs, _ = vec.reset(seed=0)
    assert obs.shape == (2, sensing_layout(get_task("push"), (6, 6, 6)).size)


@pytest.mark.parametrize("bad", ["eyes", "", None, 1, True])
def test_an_unknown_observation_is_a_typed_error(bad):
    from softgym.exceptions import InvalidParameterError

    with pytest.raises(InvalidParameterError, match="observe"):
        gym.make("SoftWalker-Flat-v0", observe=bad)
    with pytest.raises(InvalidParameterError, match="observe"):
        gym.make_vec("SoftWalker-Flat-v0", num_envs=2, vectorization_mode="vector_entry_point",
                     observe=bad)  # fmt: skip

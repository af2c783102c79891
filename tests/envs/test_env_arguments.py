"""Env arguments and actions: the types the docs promise, or a typed error naming the argument."""

import gymnasium as gym
import numpy as np
import pytest

from softgym.envs import SoftWalkerEnv, SoftWalkerVectorEnv
from softgym.exceptions import InvalidActionError, InvalidParameterError
from softgym.tasks.episode import MAX_STEPS_PER_EPISODE

SHORT = {"episode_seconds": 0.1}


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"grid_shape": (6.5, 6, 6)}, r"grid_shape must be 3 integers"),
        ({"grid_shape": "abc"}, r"grid_shape must be 3 integers"),
        ({"grid_shape": (True, 6, 6)}, r"grid_shape must be 3 integers"),
        ({"grid_shape": (6, 6)}, r"grid_shape must be 3 integers"),
        ({"grid_shape": (6, 0, 6)}, r"grid_shape .* 1\.\.1000"),
        ({"grid_shape": (1000, 1000, 1000)}, r"grid_shape .* cap of 1000000"),
        ({"self_collision": "yes"}, r"self_collision must be None, True or False"),
        ({"self_collision": 1}, r"self_collision must be None, True or False"),
        ({"max_episode_steps": -1}, r"max_episode_steps must be None or an integer in 1\.\."),
        ({"max_episode_steps": 0}, r"max_episode_steps .* 1\.\."),
        ({"max_episode_steps": 1.5}, r"max_episode_steps"),
        ({"max_episode_steps": 2.0}, r"max_episode_steps"),
        ({"max_episode_steps": True}, r"max_episode_steps"),
        ({"max_episode_steps": MAX_STEPS_PER_EPISODE + 1}, r"max_episode_steps"),
        ({"control_dt": "0.05"}, r"control_dt must be a finite number > 0"),
        ({"control_dt": True}, r"control_dt"),
        ({"control_dt": 1j}, r"control_dt"),
        ({"episode_seconds": -1.0}, r"episode_seconds must be a finite number > 0"),
        ({"episode_seconds": 1e300, "control_dt": 1e-300}, r"cap of 1000000"),
        ({"control_dt": 1e300}, r"control_dt must be at most MAX_CONTROL_DT = 10\.0 s"),
        ({"width": "abc"}, r"width must be an integer in 1\.\.4096"),
        ({"height": 0}, r"height must be an integer in 1\.\.4096"),
        ({"width": 320.0}, r"width"),
        ({"render_mode": np.array([1, 2])}, r"render_mode must be None or one of"),
        ({"drive": np.array([1, 2])}, r"drive must be one of"),
        ({"n_threads": 1.5}, r"n_threads must be an integer in 1\.\.1024"),
        ({"n_threads": 10**30}, r"n_threads"),
        ({"n_threads": "a"}, r"n_threads"),
        ({"n_threads": True}, r"n_threads"),
        ({"n_threads": 0}, r"n_threads"),
        ({"grid_shape": (6, 6, 10**5000)}, r"grid_shape"),  # too long to print
        ({"max_episode_steps": -(10**5000)}, r"max_episode_steps .* too large to print"),
    ],
)
def test_bad_arguments_raise_naming_the_argument(kwargs, match):
    with pytest.raises(InvalidParameterError, match=match):
        SoftWalkerEnv(**kwargs)
    with pytest.raises(InvalidParameterError, match=match):
        SoftWalkerVectorEnv(2, **kwargs)


def test_good_arguments_of_the_documented_types():
    env = SoftWalkerEnv(
        grid_shape=np.array([6, 7, 6]),
        self_collision=np.bool_(False),
        max_episode_steps=np.int64(3),
        control_dt=np.float32(0.05),
        **SHORT,
    )
    assert env.grid_shape == (6, 7, 6) and env.max_steps == 2
    assert env.sim.config.self_collision is False
    # a cap makes a very long episode_seconds fine: only max_episode_steps steps are kept
    with pytest.warns(UserWarning, match="ends episodes"):
        env = SoftWalkerEnv(episode_seconds=1e300, control_dt=1e-300, max_episode_steps=4)
    assert env.max_steps == 4
    with pytest.raises(InvalidParameterError, match=r"num_envs must be an integer in 1\.\.65536"):
        SoftWalkerVectorEnv(2.5)
    with pytest.raises(InvalidParameterError, match="num_envs"):
        SoftWalkerVectorEnv(10**30)  # refused before a list of 10**30 robots is made
    with pytest.raises(InvalidParameterError, match="num_envs"):
        SoftWalkerVectorEnv(True)
    for designs in (3, "walker.json", [None]):
        with pytest.raises(InvalidParameterError, match="designs"):
            SoftWalkerVectorEnv(2, designs=designs)
    with pytest.raises(InvalidParameterError, match="autoreset_mode"):
        SoftWalkerVectorEnv(2, autoreset_mode=[1])


def test_gym_make_max_episode_steps_is_gymnasiums():
    # gym.make consumes max_episode_steps for its TimeLimit (-1: no wrapper); the env never
    # sees it, so its own cap stays the episode's length
    env = gym.make("SoftWalker-Flat-v0", max_episode_steps=-1, **SHORT)
    assert not isinstance(env, gym.wrappers.TimeLimit) and env.unwrapped.max_steps == 2
    venv = gym.make_vec("SoftWalker-Flat-v0", num_envs=2, max_episode_steps=3, **SHORT)
    assert venv.max_steps == 2
    with pytest.raises(InvalidParameterError, match="max_episode_steps"):
        gym.make_vec("SoftWalker-Flat-v0", num_envs=2, max_episode_steps=-1, **SHORT)


BAD_SINGLE = [
    (np.zeros((6, 6, 6)), "shape"),  # right size, another shape: not reshaped
    (np.zeros((1, 216)), "shape"),
    (np.zeros(215), "shape"),
    (np.zeros(()), "shape"),
    (np.zeros(216, dtype=complex), "dtype complex128"),
    (np.zeros(216, dtype=bool), "dtype bool"),
    (np.zeros(216, dtype=object), "dtype object"),
    (["0.5"] * 216, "dtype <U3"),
    ([10**30] * 216, "dtype object"),  # beyond every NumPy int: object, refused
    ([[0.0], [0.0, 0.0]], "shape"),  # ragged
    (None, "dtype object"),
    (np.r_[np.zeros(215), np.nan], "NaN or infinite"),
]


def test_single_env_actions():
    env = SoftWalkerEnv(**SHORT)
    env.reset(seed=0)
    before = env.sim.get_state()
    for bad, what in BAD_SINGLE:
        with pytest.raises(InvalidActionError, match=r"real numbers of shape \(216,\)") as err:
            env.step(bad)
        assert what in str(err.value), (what, str(err.value))
    after = env.sim.get_state()
    assert all(np.array_equal(before[k], after[k]) for k in before)
    # int and float dtypes of any width are read as float64; finite values are clipped
    env.reset(seed=0)
    clipped = env.step(np.full(216, 5, np.int8))[0]
    env.reset(seed=0)
    assert np.array_equal(clipped, env.step(np.ones(216))[0])
    for good in (np.zeros(216, np.float16), np.zeros(216, np.uint8), [0] * 216, [0.0] * 216):
        env.reset(seed=0)  # a short episode: each good action starts its own
        env.step(good)


def test_vector_env_actions():
    venv = SoftWalkerVectorEnv(2, **SHORT)
    venv.reset(seed=0)
    for bad in (np.zeros(432), np.zeros((2, 6, 6, 6)), np.zeros((216, 2)), np.zeros(216)):
        with pytest.raises(InvalidActionError, match=r"shape \(2, 216\)"):
            venv.step(bad)
    with pytest.raises(InvalidActionError, match="dtype complex"):
        venv.step(np.zeros((2, 216)) + 1j)
    venv.step(np.zeros((2, 216), np.float32))
    one = SoftWalkerVectorEnv(1, **SHORT)
    one.reset(seed=0)
    with pytest.raises(InvalidActionError, match=r"shape \(1, 216\)"):
        one.step(np.zeros(216))  # a batch of one still takes (1, n_cells)
    one.step(np.zeros((1, 216)))


def test_an_env_assembles_its_engine_settings_once(monkeypatch):
    # the task's settings, the trace and the env's overrides become one SimConfig (three
    # were built per gym.make, each validated), and the task's settings are in it
    import gymnasium as gym

    from softgym.engine import config as engine_config

    built = []
    post = engine_config.SimConfig.__post_init__
    monkeypatch.setattr(engine_config.SimConfig, "__post_init__",
                        lambda self: (built.append(self), post(self))[1])  # fmt: skip
    env = gym.make("SoftWalker-Swim-v0", actuation="seed")
    assert len(built) == 1
    cfg = built[0]
    assert cfg.gravity == 0.0 and cfg.fluid_drag > 0  # the swim task's settings
    assert cfg.actuation == "seed"  # the env's override, applied last
    env.close()


@pytest.mark.parametrize("task", ["push", "gap"])
def test_reward_shaping_adds_the_tasks_guidance_and_leaves_the_score(task):
    # the return telescopes: the score, plus each shaping measure's end value times its
    # weight; without shaping the return is the score (the ids' default)
    from softgym.tasks import get_task

    shaping = get_task(task).shaping
    assert shaping
    returns, scores, ends = [], [], []
    for on in (False, True):
        env = gym.make(f"SoftWalker-{task.capitalize()}-Sensing-v0", reward_shaping=on)
        env.reset(seed=0)
        total = 0.0
        for t in range(30):
            a = np.full(env.action_space.shape, np.sin(t * 0.4 * np.pi), dtype=np.float32)
            _, r, _, _, info = env.step(np.clip(a, env.action_space.low, env.action_space.high))
            total += float(r)
        batch = env.unwrapped._batch
        ends.append(batch.shaping_value[0].copy())
        returns.append(total)
        scores.append(float(info["score"]))
        env.close()
    assert scores[0] == pytest.approx(scores[1]) and returns[0] == pytest.approx(scores[0])
    guidance = sum(w * v for (_, w), v in zip(shaping, ends[1]))
    assert guidance != 0.0
    assert returns[1] == pytest.approx(scores[1] + guidance)


def test_reward_shaping_must_be_a_bool():
    with pytest.raises(InvalidParameterError, match="reward_shaping must be True or False"):
        gym.make("SoftWalker-Push-v0", reward_shaping="yes")

"""SoftWalkerVectorEnv: N different bodies in one simulation, autoreset, equality with single envs."""

import gymnasium as gym
import numpy as np

import softgym  # noqa: F401  (registers the ids)
from softgym.design import RobotDesign, default_walker
from softgym.engine import SimConfig


def designs():
    d0 = default_walker()
    g = np.array(d0.grid)
    g[:, :, 4:] = 0
    g[:, :, 3] = 2
    small = np.zeros((4, 4, 4), dtype=np.int8)
    small[:2] = 3
    small[2:] = 4
    small[:, :, 3] = 1
    return [d0, RobotDesign(g), RobotDesign(small)]


def test_vector_env_matches_single_envs_bit_for_bit():
    ds = designs()
    venv = gym.make_vec("SoftWalker-Wall-v0", num_envs=3, designs=ds, episode_seconds=0.25)
    rng = np.random.default_rng(0)
    actions = rng.uniform(-1, 1, (7, 3, 216)).astype(np.float32)
    obs, info = venv.reset(seed=0)
    assert info["muscle_mask"].shape == (3, 216)
    vec_obs, vec_r, vec_trunc = [obs], [], []
    for a in actions:
        obs, r, term, trunc, info = venv.step(a)
        vec_obs.append(obs)
        vec_r.append(r)
        vec_trunc.append(trunc)
        assert not term.any()
    vec_r = np.array(vec_r)
    assert np.array(vec_trunc)[4].all() and not np.array(vec_trunc)[:4].any()
    # next-step autoreset: step 6 returns the first observation, reward 0
    assert np.array_equal(vec_obs[6], vec_obs[0]) and not vec_r[5].any()
    for i, d in enumerate(ds):
        env = gym.make("SoftWalker-Wall-v0", design=d, episode_seconds=0.25)
        o, _ = env.reset(seed=0)
        assert np.array_equal(o, vec_obs[0][i])
        for k in range(5):
            o, r, term, trunc, _ = env.step(actions[k, i])
            assert np.array_equal(o, vec_obs[k + 1][i])
            assert r == vec_r[k, i]
        assert trunc
        # after the autoreset the robot replays the same episode
        o, _ = env.reset()
        o, r, *_ = env.step(actions[6, i])
        assert np.array_equal(o, vec_obs[7][i]) and r == vec_r[6, i]
    venv.close()


def test_a_diverged_robot_is_reset_alone():
    bone = RobotDesign(np.full((6, 6, 6), 2, dtype=np.int8))
    # an 18 % link-strain limit flags the walker as diverged at its first driven
    # step (not while it settles), and never the stiff passive bone block
    cfg = SimConfig(max_strain=0.18, init_time=0.2)
    kw = {"sim_config": cfg, "episode_seconds": 0.15}
    venv = gym.make_vec("SoftWalker-Flat-v0", num_envs=2, designs=[default_walker(), bone], **kw)
    single = gym.make("SoftWalker-Flat-v0", design=bone, **kw)
    venv.reset(seed=0)
    single.reset(seed=0)
    walker_start, _ = gym.make("SoftWalker-Flat-v0", **kw).reset(seed=0)
    ones = np.ones((2, 216), dtype=np.float32)
    flags = []
    for k in range(3):
        obs, r, term, trunc, info = venv.step(ones)
        if k == 1:  # the autoreset observation is the fresh start
            assert np.array_equal(obs[0], walker_start)
        o1, r1, t1, tr1, _ = single.step(ones[1])
        assert np.array_equal(obs[1], o1) and r[1] == r1 and term[1] == t1 and trunc[1] == tr1
        flags.append((bool(term[0]), bool(trunc[0]), bool(info["diverged"][0]), float(r[0])))
    assert not info["diverged"][1] and trunc[1]
    # walker: diverges, is reset alone (reward 0, no flags), diverges again
    assert flags == [(True, False, True, 0.0), (False, False, False, 0.0), (True, False, True, 0.0)]


def test_same_step_autoreset_matches_next_step():
    from gymnasium.vector import AutoresetMode

    ds = designs()
    kw = {"num_envs": 3, "designs": ds, "episode_seconds": 0.15}
    nxt = gym.make_vec("SoftWalker-Flat-v0", **kw)
    same = gym.make_vec("SoftWalker-Flat-v0", autoreset_mode=AutoresetMode.SAME_STEP, **kw)
    assert same.metadata["autoreset_mode"] == AutoresetMode.SAME_STEP
    by_name = gym.make_vec("SoftWalker-Flat-v0", num_envs=1, autoreset_mode="same_step")
    assert by_name.autoreset_mode == AutoresetMode.SAME_STEP
    rng = np.random.default_rng(1)
    actions = rng.uniform(-1, 1, (4, 3, 216)).astype(np.float32)
    o_n, _ = nxt.reset(seed=0)
    o_s, _ = same.reset(seed=0)
    start = o_s.copy()
    for k in range(3):
        o_n, r_n, te_n, tr_n, i_n = nxt.step(actions[k])
        o_s, r_s, te_s, tr_s, i_s = same.step(actions[k])
        assert np.array_equal(r_n, r_s) and np.array_equal(tr_n, tr_s)
        if k < 2:
            assert np.array_equal(o_n, o_s) and "final_obs" not in i_s
    # the third step ends every episode: SAME_STEP returns the fresh start at once,
    # with the end observation and metrics NEXT_STEP returned, in final_obs/final_info
    assert tr_s.all() and i_s["_final_obs"].all()
    assert np.array_equal(o_s, start)
    assert np.array_equal(np.stack(i_s["final_obs"]), o_n)
    assert np.array_equal(i_s["final_info"]["norm_final_dist"], i_n["norm_final_dist"])
    assert (i_s["norm_final_dist"] == 0).all()
    # the next step acts at once (NEXT_STEP spends it on the reset)
    o_s, r_s, *_ = same.step(actions[3])
    assert not np.array_equal(o_s, start) and r_s.any()
    nxt.close()
    same.close()


def test_autoreset_mode_disabled_is_refused():
    import pytest
    from gymnasium.vector import AutoresetMode

    from softgym.exceptions import InvalidParameterError

    with pytest.raises(InvalidParameterError, match="SAME_STEP"):
        gym.make_vec("SoftWalker-Flat-v0", num_envs=2, autoreset_mode=AutoresetMode.DISABLED)
    with pytest.raises(InvalidParameterError, match="autoreset_mode"):
        gym.make_vec("SoftWalker-Flat-v0", num_envs=2, autoreset_mode="sometimes")


def test_same_step_resets_a_diverged_robot_alone():
    from gymnasium.vector import AutoresetMode

    bone = RobotDesign(np.full((6, 6, 6), 2, dtype=np.int8))
    cfg = SimConfig(max_strain=0.18, init_time=0.2)  # the walker diverges at its first step
    kw = {"sim_config": cfg, "episode_seconds": 0.15}
    venv = gym.make_vec(
        "SoftWalker-Flat-v0",
        num_envs=2,
        designs=[default_walker(), bone],
        autoreset_mode=AutoresetMode.SAME_STEP,
        **kw,
    )
    single = gym.make("SoftWalker-Flat-v0", design=bone, **kw)
    walker_start, _ = gym.make("SoftWalker-Flat-v0", **kw).reset(seed=0)
    venv.reset(seed=0)
    single.reset(seed=0)
    ones = np.ones((2, 216), dtype=np.float32)
    obs, r, term, trunc, info = venv.step(ones)
    o1, r1, *_ = single.step(ones[1])
    # the walker ended and restarted in the same step; the bone block went on
    assert term[0] and not term[1] and not trunc.any()
    assert list(info["_final_obs"]) == [True, False] and info["final_obs"][1] is None
    assert info["final_info"]["diverged"][0] and info["_final_info"][0]
    assert np.array_equal(obs[0], walker_start) and not info["diverged"][0]
    assert np.array_equal(obs[1], o1) and r[1] == r1
    venv.close()


def test_stepping_before_reset_raises_resetneeded_as_the_single_env():
    # issue 61: the vector env raised a plain RuntimeError, the single env ResetNeeded
    import pytest

    actions = np.zeros((2, 216), dtype=np.float32)
    venv = gym.make_vec("SoftWalker-Flat-v0", num_envs=2, episode_seconds=0.2)
    with pytest.raises(gym.error.ResetNeeded, match="reset"):
        venv.step(actions)
    env = gym.make("SoftWalker-Flat-v0", episode_seconds=0.2)
    with pytest.raises(gym.error.ResetNeeded):
        env.step(actions[0])
    venv.reset(seed=0)
    assert venv.step(actions)[0].shape[0] == 2  # after reset it steps

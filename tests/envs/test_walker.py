"""SoftWalkerEnv: determinism, action checks, rewards, divergence, the sinusoid policy."""

import gymnasium as gym
import numpy as np
import pytest

import softgym  # noqa: F401  (registers the ids)
from softgym.design import default_walker
from softgym.engine import SimConfig, Simulation
from softgym.exceptions import InvalidActionError
from softgym.metrics import norm_final_dist
from softgym.policies import Sinusoid


def rollout(env, actions, seed):
    obs, _ = env.reset(seed=seed)
    out = [obs]
    rewards = []
    for a in actions:
        obs, r, term, trunc, info = env.step(a)
        out.append(obs)
        rewards.append(r)
        if term or trunc:
            break
    return np.array(out), np.array(rewards), info


def test_same_seed_same_trajectory():
    env = gym.make("SoftWalker-Wall-v0", episode_seconds=0.3)
    rng = np.random.default_rng(5)
    actions = rng.uniform(-1, 1, (6, 216)).astype(np.float32)
    o1, r1, i1 = rollout(env, actions, seed=3)
    o2, r2, i2 = rollout(env, actions, seed=3)
    o3, r3, _ = rollout(env, actions, seed=4)  # the dynamics have no randomness
    assert np.array_equal(o1, o2) and np.array_equal(r1, r2) and i1 == i2
    assert np.array_equal(o1, o3) and np.array_equal(r1, r3)
    assert len(r1) == 6
    env.close()


def test_nan_action_raises_and_leaves_the_state_unchanged():
    env = gym.make("SoftWalker-Flat-v0", episode_seconds=0.5).unwrapped
    env.reset(seed=0)
    env.step(np.zeros(216))
    before = env.sim.get_state()
    t0 = env.time
    for bad in (np.full(216, np.nan), np.r_[np.zeros(215), np.inf], np.zeros(5)):
        with pytest.raises(InvalidActionError):
            env.step(bad)
    after = env.sim.get_state()
    assert env.time == t0
    for k in before:
        assert np.array_equal(before[k], after[k]), k


def test_out_of_range_actions_are_clipped():
    env = gym.make("SoftWalker-Flat-v0", episode_seconds=0.2)
    rng = np.random.default_rng(1)
    big = rng.uniform(-3, 3, (3, 216))
    o1, r1, _ = rollout(env, big, seed=0)
    o2, r2, _ = rollout(env, np.clip(big, -1, 1), seed=0)
    assert np.array_equal(o1, o2) and np.array_equal(r1, r2)


def test_returns_sum_to_the_task_metric_and_observations_stay_in_the_space():
    for env_id, key in (
        ("SoftWalker-Flat-v0", "norm_final_dist"),
        ("SoftWalker-Stairs-v0", "max_xy_dist"),
    ):
        env = gym.make(env_id, episode_seconds=0.5)
        policy = Sinusoid.from_env(env)
        obs, info = env.reset(seed=0)
        assert info[key] == 0.0 and info["time"] == pytest.approx(1.0)
        total = 0.0
        done = False
        while not done:
            obs, r, term, trunc, info = env.step(env.unwrapped.action_from_temperatures(policy(obs)))
            assert obs in env.observation_space
            total += r
            done = term or trunc
        assert trunc and not term and not info["diverged"]
        assert total == pytest.approx(info[key], abs=1e-12)
        assert info["time"] == pytest.approx(1.5)
        assert np.isfinite(info["l_coefficient"]) and info["l_coefficient"] >= 0


def test_divergence_terminates_the_episode():
    # dt_frac 1.6 is far above the stable bound: the driven walker blows up at once
    cfg = SimConfig(dt_frac=1.6, init_time=0.0)
    env = gym.make("SoftWalker-Flat-v0", sim_config=cfg, episode_seconds=1.0)
    obs, info = env.reset(seed=0)
    assert not info["diverged"]
    for _ in range(20):
        obs, r, term, trunc, info = env.step(np.ones(216, dtype=np.float32))
        if term or trunc:
            break
    assert term and not trunc and info["diverged"]
    assert np.isfinite(obs).all() and np.isfinite(r)
    assert info["norm_final_dist"] == softgym.metrics.WORST_FITNESS


def test_sinusoid_policy_matches_the_engines_sinusoid():
    # on the corotational step, whose gait depends smoothly on the drive (the
    # seed's step amplifies the 5 ms hold of the policy into a few % of distance)
    cfg = SimConfig.corotational()
    ref = norm_final_dist(Simulation([default_walker()], cfg, n_threads=1).run(5.0))[0]
    assert ref > 1.0  # the walker does walk
    env = gym.make("SoftWalker-Flat-v0", control_dt=0.005, sim_config=cfg, action_mode="temperature")
    policy = Sinusoid.from_env(env)
    obs, _ = env.reset(seed=0)
    done = False
    while not done:
        obs, _, term, trunc, info = env.step(policy(obs))
        done = term or trunc
    assert info["time"] == pytest.approx(5.0)  # the seed's run: 1 s settling + 4 s
    assert info["norm_final_dist"] == pytest.approx(ref, rel=0.01)


def test_sinusoid_action_at_matches_the_observed_phase():
    env = gym.make("SoftWalker-Flat-v0", episode_seconds=0.3).unwrapped
    policy = Sinusoid.from_env(env)
    obs, _ = env.reset(seed=0)
    for _ in range(3):
        np.testing.assert_allclose(policy(obs), policy.action_at(env.time), atol=1e-6)
        obs, *_ = env.step(policy(obs))
    assert policy(np.stack([obs, obs])).shape == (2, 216)


def test_a_robot_that_diverges_while_settling_ends_at_its_first_step():
    cfg = SimConfig(max_strain=0.1, init_time=0.2)  # the soft walker sags past 10 % strain
    env = gym.make("SoftWalker-Flat-v0", sim_config=cfg, episode_seconds=0.5)
    obs, info = env.reset(seed=0)
    assert info["diverged"] and obs in env.observation_space
    obs, r, term, trunc, info = env.step(np.zeros(216, dtype=np.float32))
    assert term and not trunc and r == 0.0 and info["diverged"]


def test_a_step_limit_that_cuts_the_episode_short_warns():
    import warnings

    with pytest.warns(UserWarning, match="max_episode_steps=400"):
        gym.make_vec("SoftWalker-Flat-v0", num_envs=2, control_dt=0.01, max_episode_steps=100)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        env = gym.make("SoftWalker-Flat-v0", control_dt=0.01, max_episode_steps=400)
        env.reset(seed=0)
        assert env.unwrapped.max_steps == 400
        gym.make_vec("SoftWalker-Flat-v0", num_envs=2, control_dt=0.01, max_episode_steps=400)
        gym.make("SoftWalker-Flat-v0").reset(seed=0)


@pytest.mark.parametrize("control_dt", [0.05, 0.025, 0.005])
def test_an_episode_lasts_its_seconds_whatever_the_control_step(control_dt):
    # the ids register no step limit: gym.make and make_vec both run the whole 4 s
    env = gym.make("SoftWalker-Flat-v0", control_dt=control_dt)
    env.reset(seed=0)
    steps, done = 0, False
    while not done:
        *_, term, trunc, info = env.step(np.full(216, -1.0, dtype=np.float32))
        steps += 1
        done = term or trunc
    assert trunc and steps == round(4.0 / control_dt) and info["time"] == pytest.approx(5.0)
    venv = gym.make_vec("SoftWalker-Flat-v0", num_envs=2, control_dt=control_dt)
    assert venv.max_steps == steps


def test_an_ended_episode_needs_reset_before_the_next_step():
    # issue 31: the env kept stepping after truncation; Gymnasium's convention is reset()
    env = gym.make("SoftWalker-Flat-v0", control_dt=0.05, episode_seconds=0.2).unwrapped
    with pytest.raises(gym.error.ResetNeeded):
        env.step(np.zeros(216, dtype=np.float32))  # before the first reset
    env.reset(seed=0)
    done = False
    while not done:
        *_, term, trunc, _ = env.step(np.zeros(216, dtype=np.float32))
        done = term or trunc
    with pytest.raises(gym.error.ResetNeeded, match="terminated or truncated"):
        env.step(np.zeros(216, dtype=np.float32))
    env.reset(seed=1)
    env.step(np.zeros(216, dtype=np.float32))  # a new episode steps again

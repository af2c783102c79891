"""softgym.envs.sb3: the batched vector env as a Stable-Baselines3 VecEnv (the rl extra)."""

import subprocess
import sys

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.vector import AutoresetMode

import softgym  # noqa: F401  (registers the ids)
from softgym.exceptions import InvalidParameterError


def _run(code):
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)


def test_softgym_imports_without_stable_baselines3():
    res = _run(
        "import sys; sys.modules['stable_baselines3'] = None\n"
        "import softgym, softgym.envs\n"
        "assert 'softgym.envs.sb3' not in sys.modules\n"
        "try:\n    import softgym.envs.sb3\nexcept ImportError as e:\n    print(e)\n"
    )
    assert res.returncode == 0, res.stderr
    assert 'pip install "softgym[rl]"' in res.stdout


sb3 = pytest.importorskip("stable_baselines3", reason="the rl extra (stable-baselines3) is not installed")
from softgym.envs.sb3 import SB3VecEnv, make_sb3_vec_env  # noqa: E402


def test_steps_reset_and_end_episodes_as_sb3_expects():
    env = make_sb3_vec_env("SoftWalker-Flat-v0", n_envs=3, seed=1, episode_seconds=0.2, n_threads=1)
    assert env.num_envs == 3 and env.observation_space.shape == (1301,)
    obs = env.reset()
    assert obs.shape == (3, 1301) and env.reset_infos[0]["muscle_mask"].shape == (216,)
    first = obs.copy()
    ref = gym.make("SoftWalker-Flat-v0", episode_seconds=0.2)
    ref_obs, _ = ref.reset(seed=0)
    np.testing.assert_array_equal(first[0], ref_obs)
    total = np.zeros(3)
    for k in range(4):  # 0.2 s = 4 steps
        a = np.full((3, 216), 0.5, dtype=np.float32)
        obs, rew, done, infos = env.step(a)
        ref_obs, r, term, trunc, ref_info = ref.step(a[0])
        assert rew.dtype == np.float32 and rew[0] == pytest.approx(r)
        total += rew
        assert done.all() == (k == 3)
    # the ended episode's last observation and metrics; the next episode's first observation
    np.testing.assert_array_equal(infos[0]["terminal_observation"], ref_obs)
    assert infos[0]["TimeLimit.truncated"] is True
    assert infos[0]["norm_final_dist"] == pytest.approx(ref_info["norm_final_dist"])
    assert infos[2]["score"] == pytest.approx(total[2], abs=1e-5)
    np.testing.assert_array_equal(obs, first)
    env.close()


def test_refuses_a_vector_env_that_does_not_reset_in_the_same_step():
    venv = gym.make_vec("SoftWalker-Flat-v0", num_envs=2, episode_seconds=0.2)
    with pytest.raises(InvalidParameterError, match="AutoresetMode.SAME_STEP"):
        SB3VecEnv(venv)
    with pytest.raises(InvalidParameterError, match="gymnasium.vector.VectorEnv"):
        SB3VecEnv(gym.make("SoftWalker-Flat-v0"))


def test_attributes_are_the_vector_envs():
    venv = gym.make_vec("SoftWalker-Flat-v0", num_envs=2, episode_seconds=0.2,
                        autoreset_mode=AutoresetMode.SAME_STEP, render_mode="rgb_array")  # fmt: skip
    env = SB3VecEnv(venv)
    assert env.render_mode == "rgb_array"
    assert env.get_attr("action_mode") == ["contraction", "contraction"]
    assert env.get_attr("control_dt", indices=[1]) == [0.05]
    assert env.env_is_wrapped(gym.Wrapper) == [False, False]
    with pytest.raises(AttributeError, match="share one vector env"):
        env.set_attr("control_dt", 0.1)
    with pytest.raises(AttributeError, match="not separate objects"):
        env.env_method("reset")
    env.reset()
    frames = env.get_images()
    assert len(frames) == 2 and frames[0].ndim == 3


def test_ppo_trains_on_it_with_vecnormalize():
    from stable_baselines3 import PPO
    from stable_baselines3.common.vec_env import VecMonitor, VecNormalize

    env = VecNormalize(VecMonitor(make_sb3_vec_env(n_envs=2, seed=0, episode_seconds=0.2, n_threads=1)))
    model = PPO("MlpPolicy", env, n_steps=4, batch_size=8, n_epochs=1, seed=0, device="cpu",
                policy_kwargs={"net_arch": [8]})  # fmt: skip
    model.learn(total_timesteps=16)
    # 16 env steps = 8 per robot = 2 episodes of 4 steps each
    assert model.num_timesteps == 16 and len(model.ep_info_buffer) == 4
    assert all(e["l"] == 4 for e in model.ep_info_buffer)
    assert all(np.isfinite(e["r"]) for e in model.ep_info_buffer)


def test_misordered_calls_raise_typed_errors_not_attribute_errors():
    # issue 61: step before reset and step_wait before step_async gave bare Python errors
    from softgym.exceptions import InvalidActionError

    env = make_sb3_vec_env("SoftWalker-Flat-v0", n_envs=2, seed=1, episode_seconds=0.2, n_threads=1)
    with pytest.raises(InvalidActionError, match="step_async"):
        env.step_wait()
    with pytest.raises(gym.error.ResetNeeded):
        env.step(np.zeros((2, 216), dtype=np.float32))
    env.reset()
    obs, _, _, _ = env.step(np.zeros((2, 216), dtype=np.float32))
    assert obs.shape == (2, 1301)
    env.close()

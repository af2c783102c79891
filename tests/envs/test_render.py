"""rgb_array frames and GIFs."""

import gymnasium as gym
import numpy as np
from PIL import Image

import softgym  # noqa: F401  (registers the ids)
from softgym.design import default_walker
from softgym.engine import Simulation
from softgym.render import VoxelRenderer, save_gif, simulation_frames


def test_rgb_array_frame_shows_the_robot_and_the_wall():
    env = gym.make("SoftWalker-Wall-v0", render_mode="rgb_array", episode_seconds=0.2)
    env.reset(seed=0)
    frame = env.render()
    assert frame.shape == (240, 320, 3) and frame.dtype == np.uint8
    r, g, b = (frame[..., k].astype(int) for k in range(3))
    red = (r > 120) & (g < 60) & (b < 60)  # Active_+ muscle
    green = (g > 120) & (r < 60) & (b < 60)  # Active_-
    cyan = (g > 120) & (b > 120) & (r < 60)  # the passive top layer
    wall = (r > 150) & (g > 100) & (b < 40)  # obstacle orange
    for mask in (red, green, cyan, wall):
        assert mask.sum() > 100
    env.step(env.action_space.sample())
    assert not np.array_equal(env.render(), frame)
    venv = gym.make_vec(
        "SoftWalker-Flat-v0", num_envs=2, render_mode="rgb_array", episode_seconds=0.2
    )
    venv.reset(seed=0)
    frames = venv.render()
    assert len(frames) == 2 and frames[0].shape == (240, 320, 3)
    assert np.array_equal(frames[0], frames[1])


def test_renderer_sizes_and_gif(tmp_path):
    sim = Simulation([default_walker()], n_threads=1)
    frames = simulation_frames(sim, 0.2, fps=20, renderer=VoxelRenderer(64, 48))
    assert len(frames) == 5 and frames[0].shape == (48, 64, 3)
    path = tmp_path / "walk.gif"
    assert save_gif(frames, path, fps=10) == 5
    with Image.open(path) as im:
        assert im.size == (64, 48) and im.n_frames == 5
    assert save_gif(lambda: iter(frames[:2]), tmp_path / "two.gif") == 2
    assert save_gif(sim.rollout(), tmp_path / "still.gif") == 1

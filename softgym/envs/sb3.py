"""Stable-Baselines3 adapter: a Gymnasium vector env (such as the batched SoftWalker env) as an SB3 ``VecEnv``.

SB3 has its own vector-env API (``VecEnv``: ``step_async``/``step_wait``, a
list of info dicts, ``infos[i]["terminal_observation"]``) and asks users to
adapt other vector envs to it. :class:`SB3VecEnv` adapts any Gymnasium
:class:`~gymnasium.vector.VectorEnv` in ``SAME_STEP`` autoreset mode (SB3's
convention: the step that ends an episode already returns the next one's
first observation); :func:`make_sb3_vec_env` builds the batched
:class:`~softgym.envs.vector.SoftWalkerVectorEnv` of an id for it, so all
robots advance in one engine call (no subprocesses).

Needs the ``rl`` extra (``pip install "softgym[rl]"``: stable-baselines3 and
torch). ``import softgym`` never imports this module; importing it without
stable-baselines3 raises an ImportError that says so.

Examples
--------
>>> from stable_baselines3 import PPO  # doctest: +SKIP
>>> from softgym.envs.sb3 import make_sb3_vec_env  # doctest: +SKIP
>>> model = PPO("MlpPolicy", make_sb3_vec_env("SoftWalker-Flat-v0", n_envs=16, seed=0))  # doctest: +SKIP
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv

try:
    from stable_baselines3.common.vec_env import VecEnv
except ImportError as exc:  # the rl extra is optional
    raise ImportError(
        'softgym.envs.sb3 needs stable-baselines3: pip install "softgym[rl]"'
    ) from exc

from softgym.exceptions import InvalidActionError, InvalidParameterError

__all__ = ["SB3VecEnv", "make_sb3_vec_env"]

# keys of a Gymnasium vector info dict that are not per-robot values
_VECTOR_KEYS = ("final_obs", "final_info")


def _info_dicts(info: dict[str, Any], n: int) -> list[dict[str, Any]]:
    # Gymnasium's dict of arrays (with "_key" masks) -> SB3's list of one dict per env
    out: list[dict[str, Any]] = [{} for _ in range(n)]
    for key, value in info.items():
        if key.startswith("_") or key in _VECTOR_KEYS:
            continue
        mask = info.get(f"_{key}")
        for i in range(n) if mask is None else np.flatnonzero(mask):
            out[i][key] = value[i]
    return out


class SB3VecEnv(VecEnv):
    """A Gymnasium vector env as a Stable-Baselines3 ``VecEnv``.

    Parameters
    ----------
    venv : gymnasium.vector.VectorEnv
        In ``AutoresetMode.SAME_STEP`` (``metadata["autoreset_mode"]``), e.g.
        ``gym.make_vec(id, num_envs=n, autoreset_mode=AutoresetMode.SAME_STEP)``.

    Notes
    -----
    * ``reset`` passes the seed SB3 set with :meth:`seed` (the first of its
      per-env seeds: a Gymnasium vector env takes one) and the first env's options.
    * Infos: one dict per env with the vector env's per-env values; for an
      env whose episode ended, those of the ended episode (``final_info``),
      its last observation as ``"terminal_observation"`` and
      ``"TimeLimit.truncated"`` (truncated, not terminated), as SB3's own
      vector envs report them.
    * The robots of the batched env are not separate objects: :meth:`get_attr`
      reads the vector env's attribute (the same value for every index),
      :meth:`set_attr` and :meth:`env_method` are not supported.
    """

    def __init__(self, venv: VectorEnv) -> None:
        if not isinstance(venv, VectorEnv):
            raise InvalidParameterError(
                f"venv must be a gymnasium.vector.VectorEnv, got {type(venv).__name__}"
            )
        mode = venv.metadata.get("autoreset_mode")
        if mode != AutoresetMode.SAME_STEP:
            raise InvalidParameterError(
                "venv must autoreset in AutoresetMode.SAME_STEP (SB3's convention), got "
                f"{getattr(mode, 'name', mode)}; pass autoreset_mode=AutoresetMode.SAME_STEP"
            )
        self.venv = venv
        self._actions: np.ndarray | None = None
        super().__init__(venv.num_envs, venv.single_observation_space, venv.single_action_space)

    def reset(self) -> np.ndarray:
        """Reset every env; returns the observations (``reset_infos`` holds the infos)."""
        seed = self._seeds[0]
        options = self._options[0] or None
        obs, info = self.venv.reset(seed=seed, options=options)
        self.reset_infos = _info_dicts(info, self.num_envs)
        self._reset_seeds()
        self._reset_options()
        return obs

    def step_async(self, actions: np.ndarray) -> None:
        """Store the actions for :meth:`step_wait`."""
        self._actions = actions

    def step_wait(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[dict[str, Any]]]:
        """Step every env with the stored actions: observations, rewards, dones, infos.

        Raises
        ------
        InvalidActionError
            If :meth:`step_async` has given no actions yet.
        gymnasium.error.ResetNeeded
            If the envs have not been reset (as the single env raises).
        """
        if self._actions is None:
            raise InvalidActionError("step_wait() has no actions: call step_async(actions) first")
        obs, reward, terminated, truncated, info = self.venv.step(self._actions)
        done = np.logical_or(terminated, truncated)
        infos = _info_dicts(info, self.num_envs)
        ended = np.flatnonzero(done)
        if ended.size:
            final = _info_dicts(info["final_info"], self.num_envs)
            for i in ended:
                infos[i].update(final[i])
                infos[i]["terminal_observation"] = info["final_obs"][i]
                infos[i]["TimeLimit.truncated"] = bool(truncated[i] and not terminated[i])
        return obs, np.asarray(reward, dtype=np.float32), done, infos

    def close(self) -> None:
        """Close the vector env."""
        self.venv.close()

    def get_images(self) -> Sequence[np.ndarray | None]:
        """One frame per env (the vector env's ``render()``; needs ``render_mode="rgb_array"``)."""
        frames = self.venv.render()
        return [None] * self.num_envs if frames is None else list(frames)

    def get_attr(self, attr_name: str, indices: Any = None) -> list[Any]:
        """The vector env's attribute ``attr_name``, once per index."""
        value = getattr(self.venv, attr_name)
        return [value] * len(list(self._get_indices(indices)))

    def set_attr(self, attr_name: str, value: Any, indices: Any = None) -> None:
        """Not supported: the envs share one vector env."""
        raise AttributeError(
            f"SB3VecEnv cannot set {attr_name!r} per env: the envs share one vector env "
            "(set it on .venv)"
        )

    def env_method(self, method_name: str, *args: Any, indices: Any = None, **kwargs: Any) -> list[Any]:
        """Not supported: the envs are not separate objects (call methods on ``.venv``)."""
        raise AttributeError(
            f"SB3VecEnv cannot call {method_name!r} per env: the envs are not separate objects "
            "(call it on .venv)"
        )

    def env_is_wrapped(self, wrapper_class: type[gym.Wrapper], indices: Any = None) -> list[bool]:
        """False for every env: the robots of a vector env are not wrapped envs."""
        return [False] * len(list(self._get_indices(indices)))


def make_sb3_vec_env(
    env_id: str = "SoftWalker-Flat-v0", n_envs: int = 16, seed: int | None = None, **kwargs: Any
) -> SB3VecEnv:
    """``n_envs`` robots of a SoftWalker id in one batched env, as an SB3 ``VecEnv``.

    Parameters
    ----------
    env_id : str
        A registered id (any id with a ``vector_entry_point`` in SAME_STEP autoreset).
    n_envs : int
        Robots stepped together in one engine call.
    seed : int, optional
        Seed of the first reset (the dynamics have no randomness; SB3's
        ``seed=`` of an algorithm sets it too).
    **kwargs
        The env's arguments (``control_dt``, ``design``, ``action_mode``, ...;
        see :class:`softgym.envs.walker.SoftWalkerEnv`).

    Returns
    -------
    SB3VecEnv
    """
    venv = gym.make_vec(
        env_id,
        num_envs=n_envs,
        vectorization_mode="vector_entry_point",
        autoreset_mode=AutoresetMode.SAME_STEP,
        **kwargs,
    )
    env = SB3VecEnv(venv)
    if seed is not None:
        env.seed(seed)
    return env

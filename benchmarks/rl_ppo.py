"""RL baseline: stable-baselines3 PPO on SoftWalker-Flat-v0 for a fixed budget.

Trains PPO (MLP policy, observation and reward normalisation) for
``--timesteps`` env steps on the default walker, then prints the mean episode
return (= NormFinalDist over the 4 s episode, in voxel lengths) of

* the trained policy (deterministic actions),
* a uniformly random policy,
* :class:`softgym.controllers.Sinusoid` (the seed's open-loop drive sampled
  every control step).

Needs the ``rl`` extra (``pip install -e ".[rl]"``: torch pinned to 2.13.0,
a CPU build from local disk on this machine kind; stable-baselines3). CI does
not run it.

    python benchmarks/rl_ppo.py --timesteps 20000
"""

from __future__ import annotations

import argparse
import json
import sys
import time

import gymnasium as gym
import numpy as np

import softgym  # noqa: F401  (registers the ids)
from softgym.controllers import Sinusoid

ENV_ID = "SoftWalker-Flat-v0"


def evaluate(policy, episodes: int, seed: int, control_dt: float) -> tuple[float, float]:
    """Mean and std of the episode return of ``policy(obs) -> action``."""
    env = gym.make(ENV_ID, control_dt=control_dt)
    returns = []
    for ep in range(episodes):
        obs, _ = env.reset(seed=seed + ep)
        env.action_space.seed(seed + ep)
        total, done = 0.0, False
        while not done:
            obs, r, term, trunc, _ = env.step(policy(obs, env))
            total += r
            done = term or trunc
        returns.append(total)
    env.close()
    return float(np.mean(returns)), float(np.std(returns))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--timesteps", type=int, default=20_000, help="PPO training budget (env steps)")
    ap.add_argument("--n-envs", type=int, default=8, help="parallel envs for PPO (DummyVecEnv)")
    ap.add_argument("--episodes", type=int, default=5, help="evaluation episodes per policy")
    ap.add_argument("--control-dt", type=float, default=0.05, help="seconds per action")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--json", action="store_true", help="print one JSON object as the last line")
    args = ap.parse_args(argv)
    try:
        import torch
        from stable_baselines3 import PPO
        from stable_baselines3.common.env_util import make_vec_env
        from stable_baselines3.common.vec_env import VecNormalize
    except ImportError:
        print("rl_ppo.py needs the rl extra: pip install -e '.[rl]'", file=sys.stderr)
        return 2
    torch.set_num_threads(1)
    kw = {"control_dt": args.control_dt}
    venv = VecNormalize(make_vec_env(ENV_ID, n_envs=args.n_envs, seed=args.seed, env_kwargs=kw))
    model = PPO(
        "MlpPolicy",
        venv,
        n_steps=256,
        batch_size=256,
        learning_rate=3e-4,
        seed=args.seed,
        verbose=0,
    )
    t0 = time.perf_counter()
    model.learn(total_timesteps=args.timesteps)
    train_s = time.perf_counter() - t0
    venv.training = False

    def ppo_policy(obs, env):
        norm = venv.normalize_obs(obs[None])
        return model.predict(norm, deterministic=True)[0][0]

    def ppo_sampled(obs, env):
        norm = venv.normalize_obs(obs[None])
        return model.predict(norm, deterministic=False)[0][0]

    probe = gym.make(ENV_ID, **kw)
    sinusoid = Sinusoid.from_env(probe)
    probe.close()
    results = {
        "ppo": evaluate(ppo_policy, args.episodes, args.seed + 1000, args.control_dt),
        "ppo_sampled": evaluate(ppo_sampled, args.episodes, args.seed + 1000, args.control_dt),
        "random": evaluate(
            lambda obs, env: env.action_space.sample(),
            args.episodes,
            args.seed + 1000,
            args.control_dt,
        ),
        "sinusoid": evaluate(
            lambda obs, env: sinusoid(obs), args.episodes, args.seed + 1000, args.control_dt
        ),
    }
    print(
        f"PPO on {ENV_ID}: {args.timesteps} env steps ({args.n_envs} envs, control_dt "
        f"{args.control_dt} s) in {train_s:.0f} s ({args.timesteps / train_s:.0f} steps/s incl. "
        f"updates)",
        file=sys.stderr,
    )
    print("mean episode return (NormFinalDist over 4 s, voxel lengths):", file=sys.stderr)
    for name, (mean, std) in results.items():
        print(f"  {name:<12} {mean:8.3f} +- {std:.3f}", file=sys.stderr)
    if args.json:
        print(
            json.dumps(
                {
                    "timesteps": args.timesteps,
                    "train_seconds": train_s,
                    **{k: v[0] for k, v in results.items()},
                }
            )
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""RL baseline: stable-baselines3 PPO on SoftWalker-Flat-v0 for a fixed budget.

Trains PPO (MLP policy, observation and reward normalisation) for
``--timesteps`` env steps on the default walker, then prints the mean episode
return (= NormFinalDist over the 4 s episode, in voxel lengths) of

* the trained policy (deterministic actions),
* a uniformly random policy,
* :class:`softgym.controllers.Sinusoid` (the seed's open-loop drive sampled
  every control step).

Training runs on the batched vector env (all robots in one engine call, on
every core) through :func:`sb3_vec_env`, an SB3 ``VecEnv`` adapter; ``--vec
dummy`` uses SB3's DummyVecEnv of single envs instead. ``--json`` adds the
training curve; ``plot_rl.py`` draws it.

Needs the ``rl`` extra (``pip install -e ".[rl]"``: torch pinned to 2.13.0,
a CPU build from local disk on this machine kind; stable-baselines3). CI does
not run it. Measured on 2 cores (``benchmarks/RESULTS.md``): 600k steps,
about 20 minutes, walk 26 voxel lengths with ``--actuation symmetric``
(sinusoid 9.0, random 0.08) and 0.10 under the seed's contraction-only law
(sinusoid 0.50, random 0.03).

    python benchmarks/rl_ppo.py --timesteps 20000
    python benchmarks/rl_ppo.py --timesteps 600000 --actuation symmetric --json --gif ppo.gif
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


def evaluate(policy, episodes: int, seed: int, env_kwargs: dict) -> tuple[float, float]:
    """Mean and std of the episode return of ``policy(obs) -> action``."""
    env = gym.make(ENV_ID, **env_kwargs)
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


def sb3_vec_env(env_id: str, n_envs: int, seed: int, **kwargs):
    """A Stable-Baselines3 ``VecEnv`` over the batched ``gym.make_vec`` env.

    SB3 has its own vector API and asks users to adapt others to it (its
    docs' EnvPool/ProcGen examples). All ``n_envs`` robots advance in one
    engine call (the engine's threads, no subprocesses); the env runs in
    Gymnasium's ``SAME_STEP`` autoreset mode, which is SB3's convention: the
    end observation goes to ``infos[i]["terminal_observation"]``.
    """
    from gymnasium.vector import AutoresetMode
    from stable_baselines3.common.vec_env import VecEnv

    class SoftgymVecEnv(VecEnv):
        def __init__(self) -> None:
            self.venv = gym.make_vec(
                env_id, num_envs=n_envs, autoreset_mode=AutoresetMode.SAME_STEP, **kwargs
            )
            super().__init__(
                n_envs, self.venv.single_observation_space, self.venv.single_action_space
            )
            self._actions: np.ndarray | None = None
            self._next_seed: int | None = seed

        def reset(self):
            obs, _ = self.venv.reset(seed=self._next_seed)
            self._next_seed = None
            return obs

        def step_async(self, actions: np.ndarray) -> None:
            self._actions = actions

        def step_wait(self):
            obs, rew, term, trunc, info = self.venv.step(self._actions)
            done = term | trunc
            infos: list[dict] = [{} for _ in range(self.num_envs)]
            for i in np.flatnonzero(done):
                infos[i]["terminal_observation"] = info["final_obs"][i]
                infos[i]["TimeLimit.truncated"] = bool(trunc[i] and not term[i])
            return obs, rew.astype(np.float32), done, infos

        def close(self) -> None:
            self.venv.close()

        def get_attr(self, attr_name, indices=None):
            return [getattr(self.venv, attr_name)] * len(self._get_indices(indices))

        def set_attr(self, attr_name, value, indices=None) -> None:
            raise AttributeError("SoftgymVecEnv: attributes are shared by the batch and read-only")

        def env_method(self, method_name, *args, indices=None, **kwargs):
            raise AttributeError("SoftgymVecEnv: sub-environments are not separate objects")

        def env_is_wrapped(self, wrapper_class, indices=None):
            return [False] * len(self._get_indices(indices))

    return SoftgymVecEnv()


def lattice_policy(grid_shape: tuple[int, int, int], width: int = 32):
    """An SB3 ``ActorCriticPolicy`` sharing one small network across the lattice's cells.

    The usual controller of the voxel-robot literature (one neural
    controller per voxel with shared weights, e.g. Medvet et al. 2020; Huang
    et al. 2020): each cell's action mean comes from the same MLP applied to
    that cell's observation (its 6 features) with the global entries (CM
    velocity, phase) and the cell's normalised lattice coordinates. The
    value is an MLP of the mean cell embedding and the globals. A few
    thousand weights instead of ~400k, and the policy fits any body on the
    grid.
    """
    import torch as th
    from stable_baselines3.common.policies import ActorCriticPolicy
    from torch import nn

    n_cells = int(np.prod(grid_shape))
    coords = np.stack(
        np.meshgrid(*[np.linspace(-1.0, 1.0, g) for g in grid_shape], indexing="ij"), axis=-1
    ).reshape(n_cells, 3)
    n_in = 6 + 5 + 3

    class CellExtractor(nn.Module):
        def __init__(self) -> None:
            super().__init__()
            self.latent_dim_pi = n_cells * width
            self.latent_dim_vf = width
            self.register_buffer("coords", th.as_tensor(coords, dtype=th.float32))
            self.pi = nn.Sequential(nn.Linear(n_in, width), nn.Tanh(), nn.Linear(width, width), nn.Tanh())
            self.vf_cell = nn.Sequential(nn.Linear(n_in, width), nn.Tanh())
            self.vf = nn.Sequential(nn.Linear(width + 5, width), nn.Tanh())

        def _cells(self, obs: th.Tensor) -> tuple[th.Tensor, th.Tensor]:
            b = obs.shape[0]
            glob = obs[:, 6 * n_cells :]
            cell = obs[:, : 6 * n_cells].reshape(b, n_cells, 6)
            x = th.cat(
                [cell, glob[:, None, :].expand(b, n_cells, 5), self.coords.expand(b, n_cells, 3)],
                dim=-1,
            )
            return x, glob

        def forward_actor(self, obs: th.Tensor) -> th.Tensor:
            x, _ = self._cells(obs)
            return self.pi(x).reshape(obs.shape[0], -1)

        def forward_critic(self, obs: th.Tensor) -> th.Tensor:
            x, glob = self._cells(obs)
            return self.vf(th.cat([self.vf_cell(x).mean(dim=1), glob], dim=-1))

        def forward(self, obs: th.Tensor) -> tuple[th.Tensor, th.Tensor]:
            return self.forward_actor(obs), self.forward_critic(obs)

    class CellHead(nn.Module):
        """The shared last layer: one action mean per cell from its embedding."""

        def __init__(self) -> None:
            super().__init__()
            self.linear = nn.Linear(width, 1)
            nn.init.orthogonal_(self.linear.weight, gain=0.01)
            nn.init.zeros_(self.linear.bias)

        def forward(self, latent: th.Tensor) -> th.Tensor:
            return self.linear(latent.reshape(latent.shape[0], n_cells, width)).squeeze(-1)

    class LatticePolicy(ActorCriticPolicy):
        def __init__(self, *args, **kwargs) -> None:
            kwargs["features_extractor_kwargs"] = {}
            kwargs.pop("net_arch", None)
            super().__init__(*args, **kwargs)

        def _build_mlp_extractor(self) -> None:
            self.mlp_extractor = CellExtractor()

        def _build(self, lr_schedule) -> None:
            super()._build(lr_schedule)
            if self.use_sde:
                raise ValueError("the lattice policy does not support gSDE")
            self.action_net = CellHead()
            self.optimizer = self.optimizer_class(
                self.parameters(), lr=lr_schedule(1), **self.optimizer_kwargs
            )

    return LatticePolicy


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--timesteps", type=int, default=20_000, help="PPO training budget (env steps)")
    ap.add_argument("--n-envs", type=int, default=16, help="robots stepped in parallel")
    ap.add_argument(
        "--vec",
        choices=["batched", "dummy"],
        default="batched",
        help="batched: one engine call for all robots; dummy: SB3's DummyVecEnv of single envs",
    )
    ap.add_argument("--episodes", type=int, default=5, help="evaluation episodes per policy")
    ap.add_argument("--control-dt", type=float, default=0.05, help="seconds per action")
    ap.add_argument("--actuation", choices=["seed", "symmetric"], default=None)
    ap.add_argument("--n-steps", type=int, default=128, help="rollout length per env per update")
    ap.add_argument("--batch-size", type=int, default=512)
    ap.add_argument("--n-epochs", type=int, default=10)
    ap.add_argument("--lr", type=float, default=3e-4)
    ap.add_argument("--gamma", type=float, default=0.99)
    ap.add_argument(
        "--log-std-init", type=float, default=-1.0, help="initial log std of the Gaussian policy"
    )
    ap.add_argument(
        "--sde",
        type=int,
        default=None,
        metavar="FREQ",
        help="generalized state-dependent exploration, new noise every FREQ steps (-1: per rollout)",
    )
    ap.add_argument("--net-arch", type=int, nargs="+", default=[256, 256], help="MLP policy only")
    ap.add_argument(
        "--policy",
        choices=["mlp", "lattice"],
        default="mlp",
        help="mlp: SB3's MlpPolicy; lattice: one small network shared by every cell",
    )
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--save", default=None, help="save the trained model (zip) and VecNormalize")
    ap.add_argument("--gif", default=None, help="write one episode of the trained policy to this GIF")
    ap.add_argument("--json", action="store_true", help="print one JSON object as the last line")
    ap.add_argument("--verbose", action="store_true", help="SB3's training log every update")
    args = ap.parse_args(argv)
    command = "python benchmarks/rl_ppo.py " + " ".join(sys.argv[1:] if argv is None else argv)
    t_start = time.perf_counter()
    try:
        import torch
        from stable_baselines3 import PPO
        from stable_baselines3.common.callbacks import BaseCallback
        from stable_baselines3.common.env_util import make_vec_env
        from stable_baselines3.common.vec_env import VecMonitor, VecNormalize
    except ImportError:
        print("rl_ppo.py needs the rl extra: pip install -e '.[rl]'", file=sys.stderr)
        return 2
    torch.set_num_threads(1)
    # the ids register an 80-step limit (4 s at 0.05 s): keep 4 s at any control_dt
    kw: dict = {"control_dt": args.control_dt, "max_episode_steps": round(4.0 / args.control_dt)}
    if args.actuation is not None:
        kw["actuation"] = args.actuation
    if args.vec == "batched":
        base = VecMonitor(sb3_vec_env(ENV_ID, args.n_envs, args.seed, **kw))
    else:
        base = make_vec_env(ENV_ID, n_envs=args.n_envs, seed=args.seed, env_kwargs=kw)
    venv = VecNormalize(base, gamma=args.gamma)
    # one single env tells the grid (lattice policy) and the period (sinusoid baseline)
    probe = gym.make(ENV_ID, **kw)
    sinusoid = Sinusoid.from_env(probe)
    grid_shape = probe.unwrapped.grid_shape
    preset = probe.unwrapped.sim.config.model
    probe.close()
    policy_kwargs: dict = {"log_std_init": args.log_std_init}
    if args.policy == "mlp":
        policy: object = "MlpPolicy"
        policy_kwargs["net_arch"] = list(args.net_arch)
    else:
        policy = lattice_policy(grid_shape)
    model = PPO(
        policy,
        venv,
        n_steps=args.n_steps,
        batch_size=args.batch_size,
        n_epochs=args.n_epochs,
        learning_rate=args.lr,
        gamma=args.gamma,
        use_sde=args.sde is not None,
        sde_sample_freq=-1 if args.sde is None else args.sde,
        policy_kwargs=policy_kwargs,
        seed=args.seed,
        verbose=int(args.verbose),
    )
    curve: list[tuple[int, float]] = []

    class Curve(BaseCallback):
        """Mean training-episode return (last 100 episodes) after every rollout."""

        def _on_step(self) -> bool:
            return True

        def _on_rollout_end(self) -> None:
            eps = self.model.ep_info_buffer
            if eps:
                curve.append((self.num_timesteps, float(np.mean([e["r"] for e in eps]))))

    t0 = time.perf_counter()
    model.learn(total_timesteps=args.timesteps, callback=Curve())
    train_s = time.perf_counter() - t0
    venv.training = False
    if args.save:
        model.save(args.save)
        venv.save(args.save + ".vecnormalize.pkl")

    def ppo_policy(obs, env):
        norm = venv.normalize_obs(obs[None])
        return model.predict(norm, deterministic=True)[0][0]

    def ppo_sampled(obs, env):
        norm = venv.normalize_obs(obs[None])
        return model.predict(norm, deterministic=False)[0][0]

    if args.gif:
        from softgym.render import save_gif

        env = gym.make(ENV_ID, render_mode="rgb_array", **kw)
        obs, _ = env.reset(seed=args.seed)
        frames, done = [env.render()], False
        while not done:
            obs, _, term, trunc, _ = env.step(ppo_policy(obs, env))
            frames.append(env.render())
            done = term or trunc
        save_gif(frames, args.gif, fps=env.metadata["render_fps"])
        env.close()
        print(f"wrote {args.gif} ({len(frames)} frames)", file=sys.stderr)
    results = {
        "ppo": evaluate(ppo_policy, args.episodes, args.seed + 1000, kw),
        "ppo_sampled": evaluate(ppo_sampled, args.episodes, args.seed + 1000, kw),
        "random": evaluate(
            lambda obs, env: env.action_space.sample(),
            args.episodes,
            args.seed + 1000,
            kw,
        ),
        "sinusoid": evaluate(
            lambda obs, env: sinusoid(obs), args.episodes, args.seed + 1000, kw
        ),
    }
    print(
        f"PPO on {ENV_ID} ({preset} preset): {args.timesteps} env steps ({args.n_envs} envs "
        f"{args.vec}, control_dt {args.control_dt} s) in {train_s:.0f} s ({args.timesteps / train_s:.0f} steps/s incl. "
        f"updates)",
        file=sys.stderr,
    )
    if curve:
        marks = curve[:: max(1, len(curve) // 10)] + [curve[-1]]
        print(
            "training return (last 100 episodes): "
            + ", ".join(f"{t // 1000}k {r:.3f}" for t, r in marks),
            file=sys.stderr,
        )
    print("mean episode return (NormFinalDist over 4 s, voxel lengths):", file=sys.stderr)
    for name, (mean, std) in results.items():
        print(f"  {name:<12} {mean:8.3f} +- {std:.3f}", file=sys.stderr)
    if args.json:
        print(
            json.dumps(
                {
                    "command": command,
                    "env": ENV_ID,
                    "preset": preset,
                    "timesteps": args.timesteps,
                    "train_seconds": train_s,
                    "wall_seconds": time.perf_counter() - t_start,
                    "actuation": args.actuation or "seed",
                    "control_dt": args.control_dt,
                    "n_envs": args.n_envs,
                    "episodes": args.episodes,
                    "seed": args.seed,
                    "curve": curve,
                    **{k: v[0] for k, v in results.items()},
                    "std": {k: v[1] for k, v in results.items()},
                }
            )
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())

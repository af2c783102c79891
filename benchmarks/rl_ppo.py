"""RL baseline: stable-baselines3 PPO on a SoftWalker task, checkpointed and resumable.

Trains PPO (MLP policy, observation and reward normalisation by SB3's
``VecNormalize``) for ``--timesteps`` env steps on the default walker, on the
batched vector env through :mod:`softgym.envs.sb3`, then reports the episode
return (= the task's score at the end of the episode) of

* the trained policy (deterministic actions; the start state is
  deterministic, so one episode tells it) and its sampled actions,
* uniformly random actions,
* the seed's sinusoid (:class:`softgym.policies.Sinusoid`, sampled every
  control step, turned into the env's actions by ``action_from_temperatures``).

With ``--run-dir`` the run is stored and resumable: every
``--checkpoint-every`` env steps (whole rollouts; a rollout is one episode of
every robot, so a checkpoint falls between episodes) the directory gets a new
``ckpt/`` holding the SB3 model (``model.zip``, SB3's own format: policy,
optimizer, counters; its ``data`` entry holds cloudpickled objects, so load
only checkpoints this script wrote), the ``VecNormalize`` statistics
(``vecnormalize.npz``), the RNG states (torch, NumPy, Python: ``rng.npz``,
``state.json``) and ``state.json`` (the run's record, with the SHA-256 of
every file, checked before loading). It is written as ``ckpt.new/`` and
swapped in by renames, so an interruption leaves the previous checkpoint.
Running the same command again resumes from the last checkpoint and continues
exactly as the uninterrupted run would have (``tests/test_rl_ppo.py`` checks
that the weights match). ``run.json`` (a copy of the record: command,
settings, learning curves, baselines, final evaluation) is what
``rl_table.py`` reads. ``--pause-at N`` stops at the first checkpoint at or
after N steps (e.g. to stop a run at a checkpoint).

Needs the ``rl`` extra (``pip install -e ".[rl]"``: torch pinned to 2.13.0,
stable-baselines3). Runs with one torch thread.

    python benchmarks/rl_ppo.py --timesteps 20000
    python benchmarks/rl_ppo.py --task flat --seed 0 --timesteps 500000 \\
        --run-dir benchmarks/data/rl/ppo/flat-s0
    python benchmarks/rl_ppo.py --timesteps 600000 --action-mode temperature --json  # the seed's signal
    python benchmarks/rl_ppo.py --task push --observe sensing --seed 0 --timesteps 500000 \\
        --run-dir benchmarks/data/rl/ppo/push-sensing-s0      # sees the box and the target
    python benchmarks/rl_ppo.py --task push --observe sensing --shaping --seed 0 \\
        --timesteps 500000 --run-dir benchmarks/data/rl/ppo/push-sensing-shaped-s0
        # trains on the task's dense guidance too (reward_shaping=True); scores stay the task's
"""

from __future__ import annotations

import argparse
import hashlib
import json
import random
import shutil
import sys
import time
import zipfile
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

import softgym
from softgym.envs import env_id
from softgym.policies import Sinusoid
from softgym.tasks import task_names

CKPT, CKPT_NEW, CKPT_OLD = "ckpt", "ckpt.new", "ckpt.old"
# arguments that define a run (a resumed run must be given the same ones)
RUN_ARGS = (
    "task", "seed", "n_envs", "control_dt", "episode_seconds", "actuation", "action_mode",
    "n_steps", "batch_size", "n_epochs", "lr", "gamma", "log_std_init", "net_arch",
)  # fmt: skip


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--task", default="flat", help=f"a task name ({', '.join(task_names())})")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--timesteps", type=int, default=20_000, help="PPO training budget (env steps)")
    ap.add_argument("--n-envs", type=int, default=16, help="robots stepped together")
    ap.add_argument("--control-dt", type=float, default=None, help="seconds per action (env default)")
    ap.add_argument("--episode-seconds", type=float, default=None, help="(env default: 4 s)")
    ap.add_argument("--actuation", choices=["seed", "symmetric"], default=None)
    ap.add_argument("--action-mode", choices=["contraction", "temperature"], default=None)
    ap.add_argument("--observe", choices=["blind", "sensing"], default="blind",
                    help="the observation: the voxels and a clock (the -v0 ids), or every sensor "
                         "and the task's senses (the -Sensing-v0 ids)")  # fmt: skip
    ap.add_argument("--shaping", action="store_true",
                    help="train on the task's dense guidance too (the env's reward_shaping=True: "
                         "push, push_uphill, gap); evaluations report the task's own score")  # fmt: skip
    ap.add_argument(
        "--n-steps", type=int, default=None,
        help="rollout length per env (default: one episode, so checkpoints fall between episodes)",
    )  # fmt: skip
    ap.add_argument("--batch-size", type=int, default=None, help="default: a quarter of a rollout")
    ap.add_argument("--n-epochs", type=int, default=10)
    ap.add_argument("--lr", type=float, default=3e-4)
    ap.add_argument("--gamma", type=float, default=0.99)
    ap.add_argument("--log-std-init", type=float, default=-1.0)
    ap.add_argument("--net-arch", type=int, nargs="+", default=[256, 256])
    ap.add_argument("--eval-episodes", type=int, default=4, help="for sampled/random actions")
    ap.add_argument("--run-dir", default=None, help="store (and resume) the run here")
    ap.add_argument("--checkpoint-every", type=int, default=25_000, help="env steps (with --run-dir)")
    ap.add_argument("--pause-at", type=int, default=None, help="stop at the first checkpoint >= this")
    ap.add_argument("--json", action="store_true", help="print the run's record as the last line")
    ap.add_argument("--lean", metavar="RUN_DIR", default=None,
                    help="store a finished run's checkpoint without its optimizer state, then exit")
    ap.add_argument("--verbose", action="store_true", help="SB3's training log every update")
    return ap.parse_args(argv)


def env_kwargs(args: argparse.Namespace) -> dict[str, Any]:
    """The env arguments of a run (only those given: the env's defaults otherwise)."""
    kw: dict[str, Any] = {}
    for name in ("control_dt", "episode_seconds", "actuation", "action_mode"):
        if getattr(args, name) is not None:
            kw[name] = getattr(args, name)
    return kw


# ------------------------------------------------------------------ evaluation
def run_episodes(eid: str, kw: dict, n: int, policy) -> list[float]:
    """Returns of one episode of each of ``n`` robots (one batch) under ``policy(obs, env) -> actions``."""
    env = gym.make_vec(eid, num_envs=n, vectorization_mode="vector_entry_point", n_threads=1, **kw)
    obs, _ = env.reset(seed=0)
    total = np.zeros(n)
    done = np.zeros(n, dtype=bool)
    while not done.all():
        obs, r, term, trunc, _ = env.step(policy(obs, env))
        total += np.where(done, 0.0, r)
        done |= term | trunc
    env.close()
    return total.tolist()


def baselines(eid: str, kw: dict, episodes: int, seed: int) -> dict[str, list[float]]:
    """Random actions (``episodes`` robots) and the seed's sinusoid (deterministic: one episode)."""
    rng = np.random.default_rng(seed + 1000)
    probe = gym.make_vec(eid, num_envs=1, vectorization_mode="vector_entry_point", **kw)
    sinusoid = Sinusoid.from_env(probe)
    probe.close()
    return {
        "random": run_episodes(
            eid, kw, episodes, lambda o, e: rng.uniform(-1, 1, e.action_space.shape)
        ),
        "sinusoid": run_episodes(
            eid, kw, 1, lambda o, e: e.unwrapped.action_from_temperatures(sinusoid(o))
        ),
    }


def ppo_returns(model, venv, eid: str, kw: dict, episodes: int, deterministic: bool) -> list[float]:
    """Returns of the trained policy (observations normalised with the training statistics)."""

    def policy(obs, env):
        return model.predict(venv.normalize_obs(obs), deterministic=deterministic)[0]

    return run_episodes(eid, kw, 1 if deterministic else episodes, policy)


# ------------------------------------------------------------------ checkpoints
def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


#: The member of SB3's model.zip that only resuming needs (Adam's moments: twice the policy).
OPTIMIZER_MEMBER = "policy.optimizer.pth"


def lean_model(path: Path) -> None:
    """Drop the optimizer state from a model.zip (in place, atomically): the final policy stays.

    A finished run is never resumed, so its stored checkpoint keeps the policy
    (``policy.pth``), SB3's data and the VecNormalize statistics, a third of the
    size; :func:`load_final_policy` loads it.
    """
    tmp = path.with_suffix(".lean")
    with zipfile.ZipFile(path) as z, zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as out:
        for info in z.infolist():
            if info.filename != OPTIMIZER_MEMBER:
                out.writestr(info.filename, z.read(info.filename))
    tmp.replace(path)


def save_checkpoint(run_dir: Path, model, venv, record: dict) -> None:
    """Write ``ckpt.new/`` (model, VecNormalize, RNG states, record) and swap it in.

    A finished run's model is stored lean (:func:`lean_model`: no optimizer state).
    """
    import torch

    new, cur, old = run_dir / CKPT_NEW, run_dir / CKPT, run_dir / CKPT_OLD
    shutil.rmtree(new, ignore_errors=True)
    new.mkdir(parents=True)
    model.save(new / "model.zip")
    if record.get("finished"):
        lean_model(new / "model.zip")
    np.savez(
        new / "vecnormalize.npz",
        obs_mean=venv.obs_rms.mean, obs_var=venv.obs_rms.var, obs_count=venv.obs_rms.count,
        ret_mean=venv.ret_rms.mean, ret_var=venv.ret_rms.var, ret_count=venv.ret_rms.count,
        returns=venv.returns,
    )  # fmt: skip
    # SB3 shuffles minibatches with the legacy global NumPy RNG: its state is part of the run
    kind, keys, pos, has_gauss, cached = np.random.get_state()  # noqa: NPY002
    np.savez(
        new / "rng.npz",
        torch=torch.get_rng_state().numpy(), np_keys=keys,
        np_rest=np.array([pos, has_gauss, cached], dtype=np.float64),
    )  # fmt: skip
    state = dict(record)
    state["python_random"] = [random.getstate()[0], list(random.getstate()[1]), random.getstate()[2]]
    state["files"] = {f.name: _sha256(f) for f in sorted(new.iterdir())}
    (new / "state.json").write_text(json.dumps(state))
    if cur.exists():
        shutil.rmtree(old, ignore_errors=True)
        cur.rename(old)
    new.rename(cur)
    shutil.rmtree(old, ignore_errors=True)
    tmp = run_dir / "run.json.new"
    tmp.write_text(json.dumps(record, indent=1))
    tmp.replace(run_dir / "run.json")


def find_checkpoint(run_dir: Path) -> Path | None:
    """The last complete checkpoint (``ckpt/``, or ``ckpt.old/`` if a swap was interrupted)."""
    for name in (CKPT, CKPT_OLD):
        if (run_dir / name / "state.json").exists():
            return run_dir / name
    return None


def make_lean(run_dir: Path) -> None:
    """Store a finished run's checkpoint lean (:func:`lean_model`), its checksums updated."""
    ckpt = Path(run_dir) / CKPT
    state = json.loads((ckpt / "state.json").read_text())
    if not state.get("finished"):
        raise SystemExit(f"{run_dir}: not finished; an unfinished run keeps its optimizer to resume")
    lean_model(ckpt / "model.zip")
    state["files"] = {name: _sha256(ckpt / name) for name in state["files"]}
    (ckpt / "state.json").write_text(json.dumps(state))


def load_final_policy(run_dir: Path) -> tuple[Any, Any, str, dict]:
    """A finished run's final policy on a fresh single env: ``(model, venv, env id, env kwargs)``.

    The policy's weights from the stored ``policy.pth`` and the observation
    statistics from ``vecnormalize.npz`` (checksums checked), in a PPO of the
    run's settings; ``model.predict(venv.normalize_obs(obs))`` acts as it did.
    """
    from stable_baselines3 import PPO
    from stable_baselines3.common.save_util import load_from_zip_file
    from stable_baselines3.common.vec_env import VecMonitor, VecNormalize

    from softgym.envs.sb3 import make_sb3_vec_env

    ckpt = Path(run_dir) / CKPT
    state = json.loads((ckpt / "state.json").read_text())
    for name, digest in state["files"].items():
        if _sha256(ckpt / name) != digest:
            raise SystemExit(f"{ckpt / name}: checksum mismatch; not loading it")
    st, eid, kw = state["settings"], state["env"], state["env_kwargs"]
    venv = VecNormalize(VecMonitor(make_sb3_vec_env(eid, n_envs=1, seed=st["seed"], n_threads=1, **kw)),
                        gamma=st["gamma"], training=False)  # fmt: skip
    with np.load(ckpt / "vecnormalize.npz", allow_pickle=False) as z:
        venv.obs_rms.mean, venv.obs_rms.var, venv.obs_rms.count = z["obs_mean"], z["obs_var"], float(z["obs_count"])
    model = PPO("MlpPolicy", venv, device="cpu", policy_kwargs={
        "log_std_init": st["log_std_init"], "net_arch": list(st["net_arch"])})  # fmt: skip
    _, params, _ = load_from_zip_file(ckpt / "model.zip", device="cpu")
    model.policy.load_state_dict(params["policy"])
    return model, venv, eid, kw


def load_checkpoint(ckpt: Path, venv, model_cls) -> tuple[Any, dict]:
    """The model (on ``venv``) and record of a checkpoint; restores VecNormalize and the RNGs."""
    import torch

    state = json.loads((ckpt / "state.json").read_text())
    for name, digest in state["files"].items():
        if _sha256(ckpt / name) != digest:
            raise SystemExit(f"{ckpt / name}: checksum mismatch; not loading it")
    model = model_cls.load(ckpt / "model.zip", env=venv, device="cpu", force_reset=False)
    with np.load(ckpt / "vecnormalize.npz", allow_pickle=False) as z:
        venv.obs_rms.mean, venv.obs_rms.var, venv.obs_rms.count = z["obs_mean"], z["obs_var"], float(z["obs_count"])
        venv.ret_rms.mean, venv.ret_rms.var, venv.ret_rms.count = z["ret_mean"], z["ret_var"], float(z["ret_count"])
        returns = z["returns"]
    # the robots are between episodes: restart them without counting the start observation
    # twice in the statistics (the uninterrupted run saw it once, as the last step's)
    venv.training = False
    venv.reset()
    venv.training = True
    venv.returns = returns
    with np.load(ckpt / "rng.npz", allow_pickle=False) as z:
        torch.set_rng_state(torch.from_numpy(z["torch"]))
        pos, has_gauss, cached = z["np_rest"]
        np.random.set_state(("MT19937", z["np_keys"], int(pos), int(has_gauss), float(cached)))  # noqa: NPY002
    v, internal, gauss = state["python_random"]
    random.setstate((v, tuple(internal), gauss))
    # (the zip holds the model's counters, last observation and episode buffer)
    return model, state


# ------------------------------------------------------------------ main
def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    if args.lean:
        make_lean(Path(args.lean))
        return 0
    raw = sys.argv[1:] if argv is None else list(argv)
    shown = [a for i, a in enumerate(raw) if a != "--pause-at" and (i == 0 or raw[i - 1] != "--pause-at")]
    command = "python benchmarks/rl_ppo.py " + " ".join(shown)
    if args.task not in task_names():
        raise SystemExit(f"--task must be one of {', '.join(task_names())}, got {args.task!r}")
    try:
        import stable_baselines3
        import torch
        from stable_baselines3 import PPO
        from stable_baselines3.common.vec_env import VecMonitor, VecNormalize

        from softgym.envs.sb3 import make_sb3_vec_env
    except ImportError:
        print("rl_ppo.py needs the rl extra: pip install -e '.[rl]'", file=sys.stderr)
        return 2
    torch.set_num_threads(1)
    eid = env_id(args.task, sensing=args.observe == "sensing")
    kw = env_kwargs(args)
    probe = gym.make(eid, **kw).unwrapped
    episode_steps, action_mode, preset = probe.max_steps, probe.action_mode, probe.sim.config.model
    control_dt = probe.control_dt
    probe.close()
    if args.n_steps is None:
        args.n_steps = episode_steps
    if args.batch_size is None:
        args.batch_size = max(1, args.n_steps * args.n_envs // 4)
    settings = {k: getattr(args, k) for k in RUN_ARGS}
    if args.observe != "blind":  # (the blind runs' records predate the option)
        settings["observe"] = args.observe
    if args.shaping:  # the training env's reward only: evaluations use the task's score
        settings["shaping"] = True
    train_kw = {**kw, "reward_shaping": True} if args.shaping else kw
    rollout = args.n_steps * args.n_envs
    run_dir = Path(args.run_dir) if args.run_dir else None
    ckpt = find_checkpoint(run_dir) if run_dir else None

    venv = VecNormalize(
        VecMonitor(make_sb3_vec_env(eid, n_envs=args.n_envs, seed=args.seed, n_threads=1, **train_kw)),
        gamma=args.gamma,
    )
    if ckpt is not None and json.loads((ckpt / "state.json").read_text()).get("finished"):
        record = json.loads((run_dir / "run.json").read_text())
        if args.timesteps > record["timesteps"]:
            raise SystemExit(f"{run_dir} finished at {record['timesteps']} env steps and keeps its "
                             "final policy only (no optimizer state): start a new --run-dir")  # fmt: skip
        print(f"{run_dir}: finished", file=sys.stderr)
        ckpt = None
        model = None
    elif ckpt is not None:
        model, record = load_checkpoint(ckpt, venv, PPO)
        if record["settings"] != settings:
            diff = {k: (record["settings"].get(k), v) for k, v in settings.items() if record["settings"].get(k) != v}
            raise SystemExit(f"{run_dir} holds a run with other settings (stored, given): {diff}")
        for key in ("python_random", "files"):
            record.pop(key, None)
        record["timesteps"] = args.timesteps
        record["command"] = command
        print(f"resuming {run_dir} at {model.num_timesteps} env steps", file=sys.stderr)
    else:
        model = PPO(
            "MlpPolicy", venv, n_steps=args.n_steps, batch_size=args.batch_size,
            n_epochs=args.n_epochs, learning_rate=args.lr, gamma=args.gamma,
            policy_kwargs={"log_std_init": args.log_std_init, "net_arch": list(args.net_arch)},
            seed=args.seed, device="cpu", verbose=int(args.verbose),
        )  # fmt: skip
        record = {
            "command": command,
            "env": eid,
            "task": args.task,
            "env_kwargs": kw,
            "action_mode": action_mode,
            "control_dt": control_dt,
            "preset": preset,
            "settings": settings,
            "timesteps": args.timesteps,
            "num_timesteps": 0,
            "train_seconds": 0.0,
            "curve": [],
            "eval_curve": [],
            "baselines": baselines(eid, kw, args.eval_episodes, args.seed),
            "versions": {
                "softgym": softgym.__version__,
                "stable_baselines3": stable_baselines3.__version__,
                "torch": torch.__version__,
            },
            "finished": False,
        }
    target = args.timesteps if args.pause_at is None else min(args.timesteps, args.pause_at)
    every = max(rollout, -(-args.checkpoint_every // rollout) * rollout) if run_dir else target
    first = ckpt is None
    while model is not None and model.num_timesteps < target:
        t0 = time.perf_counter()
        chunk = min(every, -(-(target - model.num_timesteps) // rollout) * rollout)
        start = model.num_timesteps
        model.learn(total_timesteps=chunk, reset_num_timesteps=first, progress_bar=False)
        first = False
        record["train_seconds"] += time.perf_counter() - t0
        record["num_timesteps"] = int(model.num_timesteps)
        if model.ep_info_buffer:
            record["curve"].append(
                [int(model.num_timesteps), float(np.mean([e["r"] for e in model.ep_info_buffer]))]
            )
        det = ppo_returns(model, venv, eid, kw, 1, deterministic=True)[0]
        record["eval_curve"].append([int(model.num_timesteps), det])
        print(
            f"{eid} seed {args.seed}: {model.num_timesteps} steps ({model.num_timesteps - start} in "
            f"{time.perf_counter() - t0:.0f} s), training return {record['curve'][-1][1] if record['curve'] else float('nan'):.3f}, "
            f"deterministic {det:.3f}",
            file=sys.stderr,
            flush=True,
        )
        if model.num_timesteps >= args.timesteps:
            record["final"] = {
                "ppo": det,
                "ppo_sampled": ppo_returns(model, venv, eid, kw, args.eval_episodes, False),
            }
            record["finished"] = True
        if run_dir:
            save_checkpoint(run_dir, model, venv, record)
    if record.get("final"):
        b = record["baselines"]
        print(
            f"{eid}: PPO {record['final']['ppo']:.3f} (sampled {np.mean(record['final']['ppo_sampled']):.3f}), "
            f"random {np.mean(b['random']):.3f}, sinusoid {b['sinusoid'][0]:.3f} "
            f"after {record['num_timesteps']} env steps, {record['train_seconds']:.0f} s",
            file=sys.stderr,
        )
    if args.json:
        print(json.dumps(record))
    return 0


if __name__ == "__main__":
    sys.exit(main())

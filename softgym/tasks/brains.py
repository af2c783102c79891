"""Closed-loop control of a batch: every robot's brain reads its senses and sets its muscles.

:class:`BrainDrive` is the control step of the designs' brains (:class:`~softgym.design.Brain`) in
an :class:`~softgym.tasks.EpisodeBatch` (``drive="brain"``): the sensors of
every robot are read at once (:class:`~softgym.tasks.sensing.Sensing`), the
networks of every robot that share a :class:`~softgym.design.BrainSpec` run
as one batched product (:func:`softgym.design.brain.forward`), and the
outputs become muscle temperatures through the envs' own
:class:`~softgym.tasks.ActionMap`. :func:`brain_spec` gives the sizes of a
brain for a task and grid; :func:`run_brains` scores designs that carry
brains (what :func:`softgym.evaluate` calls for them).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from softgym.design import RobotDesign
from softgym.design.brain import WEIGHT_BOUND, Brain, BrainSpec, forward
from softgym.exceptions import InvalidDesignError, InvalidParameterError
from softgym.tasks.sensing import CELL_SENSORS, ROBOT_SENSORS, sensing_layout
from softgym.tasks.task import Task
from softgym.validate import show

__all__ = ["BrainDrive", "brain_spec", "run_brains", "sinusoid_brain"]

#: One step along each lattice axis, both ways: the distributed brains' six neighbours.
#: Index of ``clock_sin`` among the robot sensors.
_CLOCK_SIN = [name for name, _, _ in ROBOT_SENSORS].index("clock_sin")
_NEIGHBOURS: tuple[tuple[int, int], ...] = ((0, 1), (0, -1), (1, 1), (1, -1), (2, 1), (2, -1))


def brain_spec(
    kind: str,
    task: Task,
    grid_shape: Sequence[int],
    hidden: int = 8,
    signals: int | None = None,
    control_dt: float = 0.05,
) -> BrainSpec:
    """The :class:`~softgym.design.BrainSpec` of a brain for ``task`` on ``grid_shape``.

    Parameters
    ----------
    kind : {"central", "distributed"}
    task : Task
        Its senses set the inputs.
    grid_shape : 3 ints
        A central brain's grid (inputs and outputs); unused by a distributed
        one, whose sizes hold for any body.
    hidden : int
        Hidden units.
    signals : int, optional
        A distributed brain's signals per neighbour (default 1; 0 for central).
    control_dt : float
        Seconds between control steps.
    """
    layout = sensing_layout(task, grid_shape)
    if kind == "central":
        if signals:
            raise InvalidParameterError(f"a central brain sends no signals, got signals={show(signals)}")
        return BrainSpec("central", layout.size, layout.n_cells, hidden, 0, control_dt)
    if kind == "distributed":
        s = 1 if signals is None else signals
        if isinstance(s, (bool, np.bool_)) or not isinstance(s, (int, np.integer)) or s < 0:
            raise InvalidParameterError(f"signals must be an integer >= 0, got {show(signals)}")
        return BrainSpec("distributed", layout.local_size + 6 * int(s), 1 + int(s), hidden, int(s),
                         control_dt)  # fmt: skip
    raise InvalidParameterError(f"brain kind must be 'central' or 'distributed', got {show(kind)}")


def sinusoid_brain(spec: BrainSpec, gain: float = 2.0) -> Brain:
    """The brain that drives every muscle with the clock alone: the seed's gait as a network.

    Every weight is 0 but the path from the clock's ``sin`` input to the
    actuation output (through hidden unit 0 when there is a hidden layer),
    each ``gain``: the output is ``tanh(gain tanh(gain sin(2 pi t / period)))``
    on every muscle, which the contraction map turns into the two muscle
    kinds' counter-phase (the sinusoid's gait, squarer). A start for an
    optimiser that then adds what the senses tell.
    """
    # the inputs: a central brain's cells (8 each) or a voxel's own cell, then the robot's
    cells = len(CELL_SENSORS) * (spec.n_outputs if spec.kind == "central" else 1)
    clock = cells + _CLOCK_SIN
    g = float(min(max(gain, -WEIGHT_BOUND), WEIGHT_BOUND))
    w = np.zeros(spec.n_params)
    shapes = spec.layer_shapes()
    if spec.hidden == 0:
        rows, cols = shapes[0]
        m = w[: rows * cols].reshape(rows, cols)
        if spec.kind == "central":
            m[:, clock] = g
        else:
            m[0, clock] = g
        return spec.brain(w)
    (r1, c1), (r2, c2) = shapes
    m1 = w[: r1 * c1].reshape(r1, c1)
    m1[0, clock] = g
    m2 = w[r1 * c1:].reshape(r2, c2)
    if spec.kind == "central":
        m2[:, 0] = g
    else:
        m2[0, 0] = g
    return spec.brain(w)


class BrainDrive:
    """The brains of every robot of a batch, run as batched products.

    Parameters
    ----------
    batch : EpisodeBatch
        Every design must carry a brain whose sizes fit the batch's task and
        grid and whose ``control_dt`` is the batch's.

    Raises
    ------
    InvalidDesignError
        Naming the first design whose brain is missing or does not fit.
    """

    def __init__(self, batch: Any) -> None:
        from softgym.tasks.actions import ActionMap

        self.batch = batch
        layout = sensing_layout(batch.task, batch.grid_shape)
        self.layout = layout
        groups: dict[BrainSpec, list[int]] = {}
        for i, d in enumerate(batch.designs):
            b = d.brain
            if b is None:
                raise InvalidDesignError(f"design {i} has no brain (drive='brain' needs one per design)")
            s = b.spec
            if s.kind == "central":
                want = (layout.size, layout.n_cells)
                what = f"task {batch.task.name!r} on grid {batch.grid_shape}"
            else:
                want = (layout.local_size + 6 * s.signals, 1 + s.signals)
                what = f"task {batch.task.name!r} (per voxel, {s.signals} signals)"
            if (s.n_inputs, s.n_outputs) != want:
                raise InvalidDesignError(
                    f"design {i}'s {s.kind} brain has n_inputs={s.n_inputs}, n_outputs={s.n_outputs}; "
                    f"{what} needs n_inputs={want[0]}, n_outputs={want[1]} "
                    f"(softgym.tasks.brain_spec gives the sizes)"
                )
            if abs(s.control_dt - batch.control_dt) > 1e-12:
                raise InvalidDesignError(
                    f"design {i}'s brain has control_dt={s.control_dt} s, the batch steps "
                    f"every {batch.control_dt} s"
                )
            groups.setdefault(s, []).append(i)
        self.groups = [
            (spec, np.asarray(ids, dtype=np.intp),
             np.stack([batch.designs[i].brain.weights for i in ids]))
            for spec, ids in groups.items()
        ]  # fmt: skip
        self.scales = layout.scales()
        self.local_scales = layout.local_scales()
        n, nc = batch.n_robots, batch.n_cells
        self.mask = batch.filled_mask.reshape(n, nc)
        self.signals = {
            k: np.zeros((len(ids), nc, spec.signals))
            for k, (spec, ids, _) in enumerate(self.groups)
            if spec.kind == "distributed"
        }
        self.action_map = ActionMap(batch, None)

    def reset(self, ids: np.ndarray | None = None) -> None:
        """Silence the distributed brains' signals of the robots ``ids`` (default all)."""
        for k, sig in self.signals.items():
            if ids is None:
                sig[:] = 0.0
            else:
                sig[np.isin(self.groups[k][1], ids)] = 0.0

    def _neighbour_signals(self, sig: np.ndarray) -> np.ndarray:
        # what each cell hears from its six lattice neighbours: (k, nc, 6 * S), empty beyond the grid
        k, nc, s = sig.shape
        g = sig.reshape(k, *self.batch.grid_shape, s)
        out = np.zeros((k, *self.batch.grid_shape, 6, s))
        for j, (axis, step) in enumerate(_NEIGHBOURS):
            src = [slice(None)] * 5
            dst = [slice(None)] * 4
            if step > 0:  # the neighbour at +1 along the axis
                src[axis + 1], dst[axis + 1] = slice(1, None), slice(None, -1)
            else:
                src[axis + 1], dst[axis + 1] = slice(None, -1), slice(1, None)
            out[(*dst, j, slice(None))] = g[tuple(src)]
        return out.reshape(k, nc, 6 * s)

    def outputs(self) -> np.ndarray:
        """Every robot's network outputs now, one per cell in [-1, 1], shape (n_robots, n_cells)."""
        b = self.batch
        cells, robot, task = b.sensing.read(b.clock(), b.period)
        n, nc = b.n_robots, b.n_cells
        out = np.zeros((n, nc))
        nc_cell = cells.shape[2]
        shared = np.concatenate([robot, task], axis=1) / self.local_scales[nc_cell:]
        for k, (spec, ids, w) in enumerate(self.groups):
            if spec.kind == "central":
                x = np.concatenate([cells[ids].reshape(len(ids), -1), robot[ids], task[ids]], axis=1)
                out[ids] = forward(spec, w, (x / self.scales)[:, None, :])[:, 0, :]
                continue
            parts = [cells[ids] / self.local_scales[:nc_cell], shared[ids][:, None, :]]
            if spec.signals:
                parts.append(self._neighbour_signals(self.signals[k]))
            y = forward(spec, w, parts)
            out[ids] = y[..., 0]
            if spec.signals:
                self.signals[k] = y[..., 1:] * self.mask[ids][:, :, None]
        return out * self.mask

    def step(self) -> None:
        """Read the senses and set every robot's muscles for the next control step."""
        self.batch.apply(self.action_map(self.outputs()), force=True)


def run_brains(
    designs: Sequence[RobotDesign],
    task: Task,
    config: Any,
    n_threads: int | None = None,
) -> tuple[dict[str, np.ndarray], list[np.ndarray]]:
    """Score designs that carry brains on ``task``: control episodes in batches.

    Designs are batched by their brains' control step (and a central brain's
    grid); a distributed batch runs on the largest body's grid. Each robot
    settles for ``config.init_time`` with idle muscles, then its brain drives
    it for the rest of ``task.seconds``, one control step at a time, and the
    task's metrics come from the centre of mass sampled every
    ``task.trace_interval`` (the open loop's sampling) where that is a whole
    number of control steps, else at every control step
    (:meth:`softgym.tasks.EpisodeBatch.metrics`).

    Returns
    -------
    metrics : dict of str to ndarray (n_designs,)
    traces : list of ndarray (n_points, 4)
        Each robot's centre-of-mass samples (x, y, z, t), m and s, from the
        episode start.
    """
    from softgym.tasks.episode import EpisodeBatch

    designs = list(designs)
    episode = float(task.seconds) - float(config.init_time)
    if episode <= 0:
        raise InvalidParameterError(
            f"seconds = {task.seconds} must outlast the settling time init_time = "
            f"{config.init_time} s for a brain to act"
        )
    groups: dict[tuple[float, Any], list[int]] = {}
    for i, d in enumerate(designs):
        if d.brain is None:
            raise InvalidDesignError(f"design {i} has no brain")
        s = d.brain.spec
        key = (s.control_dt, d.shape if s.kind == "central" else None)
        groups.setdefault(key, []).append(i)
    out: dict[str, np.ndarray] = {}
    traces: list[np.ndarray] = [np.zeros((0, 4))] * len(designs)
    for (dt, grid), ids in groups.items():
        batch_designs = [designs[i] for i in ids]
        shape = grid if grid is not None else tuple(
            int(v) for v in np.max([d.shape for d in batch_designs], axis=0)
        )
        batch = EpisodeBatch(batch_designs, task, shape, dt, episode, None, config,
                             n_threads=n_threads, drive="brain")  # fmt: skip
        batch.reset_all()
        every = np.ones(batch.n_robots, dtype=bool)
        for _ in range(batch.max_steps):
            batch.brains.step()
            batch.advance()
            batch.update(every)
        ratio = float(task.trace_interval) / dt
        stride = int(round(ratio)) if round(ratio) >= 1 and abs(ratio - round(ratio)) < 1e-9 else 1
        m = batch.metrics(stride)
        for key, v in m.items():
            if key not in out:
                out[key] = np.zeros(len(designs), dtype=v.dtype)
            out[key][ids] = v
        for j, i in enumerate(ids):
            traces[i] = batch.trace(j)
    return out, traces

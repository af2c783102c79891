"""Variation operators of the seed study (docs/PHYSICS.md).

* :func:`mut_cppn`: one NEAT-style CPPN mutation, retried until the body
  changes and stays valid (up to 1500 attempts).
* :func:`cx_arithmetic`: arithmetic crossover of the real-valued genes: the
  first ``floor(rate * pop_size)`` (shuffled) children take the mean of two
  distinct random parents' controller and/or material genes.
* :func:`mut_controller`, :func:`mut_materials`: bounded Gaussian mutation
  with the seed's sigmas and bounds.
* :func:`mut_brain`: bounded Gaussian mutation of a network controller's
  weights (clipped to ``+-WEIGHT_BOUND``); :func:`cx_arithmetic` averages
  two parents' weights when brains evolve.
* :func:`make_children`: the whole variation step of one generation.

Every function takes an explicit ``numpy.random.Generator``.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np

from evolvers.operators.genome import Individual
from softgym.design import CONTROLLER_BOUNDS, CompositionRules, Controller
from softgym.design.brain import WEIGHT_BOUND

__all__ = [
    "BRAIN_SIGMA",
    "CONTROLLER_SIGMAS",
    "MATERIAL_MUTATION",
    "cx_arithmetic",
    "make_children",
    "mut_brain",
    "mut_controller",
    "mut_cppn",
    "mut_materials",
    "set_counterphase",
]

#: Gaussian sigma per controller gene (§3.2); bounds are :data:`softgym.design.CONTROLLER_BOUNDS`.
CONTROLLER_SIGMAS: dict[str, float] = {"temp_amplitude": 1.0, "period": 0.1, "muscle_cte": 0.01}

#: Gaussian sigma of a brain weight's mutation (weights lie in [-WEIGHT_BOUND, WEIGHT_BOUND] = [-3, 3]).
BRAIN_SIGMA = 0.1

#: Material-gene mutation (§3.1): (row of id, column, sigma, low, high); applied in this order.
#: Rows: 0 = id 6 (soft tissue), 1 = id 7 (hard tissue), 2 = id 8 (muscle); columns E, density, CTE.
MATERIAL_MUTATION: tuple[tuple[int, int, float, float, float], ...] = (
    (0, 1, 1e5, 1e3, 1e7),  # id 6 density
    (0, 0, 5e3, 5e6, 5e8),  # id 6 Young's modulus
    (1, 1, 1e5, 1e3, 1e7),  # id 7 density
    (1, 0, 5e3, 5e6, 5e8),  # id 7 Young's modulus
    (2, 1, 1e5, 1e3, 1e7),  # id 8 density
    (2, 2, 0.01, 0.001, 0.04),  # id 8 CTE
)


def _rng(rng: np.random.Generator | int | None) -> np.random.Generator:
    return rng if isinstance(rng, np.random.Generator) else np.random.default_rng(rng)


def set_counterphase(materials: np.ndarray) -> None:
    """Material 9 := material 8 with the opposite CTE (in place).

    Parameters
    ----------
    materials : ndarray of shape (4, 3), float64
        Material genes (rows: ids 6-9; columns: Young's modulus, density, CTE).
    """
    materials[3, 0] = materials[2, 0]
    materials[3, 1] = materials[2, 1]
    materials[3, 2] = -materials[2, 2]


def mut_cppn(
    ind: Individual,
    rng: np.random.Generator | int | None,
    shape: Sequence[int] = (6, 6, 6),
    rules: CompositionRules | Callable[[np.ndarray], bool] | None = None,
    max_attempts: int = 1500,
) -> bool:
    """Mutate the CPPN of ``ind`` in place until its body changes and stays valid.

    Returns
    -------
    bool
        False when no valid, phenotype-changing mutation was found (the genome is kept).
    """
    res = ind.cppn.mutate(_rng(rng), shape=tuple(shape), is_valid=rules, max_attempts=max_attempts)
    ind.cppn = res.genome
    ind._grid = None
    return res.success


def mut_controller(
    ind: Individual,
    rng: np.random.Generator | int | None,
    sigmas: dict[str, float] | None = None,
) -> Individual:
    """Bounded Gaussian mutation of the controller genes (in place; returns ``ind``).

    Each gene gets ``N(0, sigma)`` added, then is clipped into
    :data:`~softgym.design.CONTROLLER_BOUNDS` (amplitude [1, 20] °C, period
    [0.01, 0.75] s, muscle CTE [0.001, 0.04] 1/°C).
    """
    rng = _rng(rng)
    sigmas = CONTROLLER_SIGMAS if sigmas is None else sigmas
    c = ind.controller
    values = {name: getattr(c, name) for name in CONTROLLER_BOUNDS}
    for name in CONTROLLER_BOUNDS:  # fixed order: amplitude, period, CTE
        values[name] = values[name] + float(rng.normal(0.0, sigmas[name]))
    ind.controller = Controller.clipped(**values)
    return ind


def mut_brain(
    ind: Individual, rng: np.random.Generator | int | None, sigma: float = BRAIN_SIGMA
) -> Individual:
    """Bounded Gaussian mutation of the brain's weights (in place; returns ``ind``).

    Every weight gets ``N(0, sigma)`` added (one draw of the whole vector),
    then is clipped into ``[-WEIGHT_BOUND, WEIGHT_BOUND]``. An individual
    without a brain is left as it is (no draw).
    """
    if ind.brain is None:
        return ind
    rng = _rng(rng)
    w = ind.brain + rng.normal(0.0, float(sigma), size=ind.brain.shape)
    ind.brain = np.clip(w, -WEIGHT_BOUND, WEIGHT_BOUND)
    return ind


def mut_materials(ind: Individual, rng: np.random.Generator | int | None) -> Individual:
    """Bounded Gaussian mutation of the material genes (in place; returns ``ind``).

    Density of 6, 7, 8 (sigma 1e5 kg/m^3, [1e3, 1e7]); Young's modulus of
    the tissues 6, 7 (sigma 5000 Pa, [5e6, 5e8]); CTE of the muscle 8
    (sigma 0.01, [0.001, 0.04] 1/°C). Material 9 then becomes the
    counter-phase copy of 8 (§3.1).
    """
    rng = _rng(rng)
    m = ind.materials
    for row, col, sigma, lo, hi in MATERIAL_MUTATION:
        m[row, col] = min(max(m[row, col] + float(rng.normal(0.0, sigma)), lo), hi)
    set_counterphase(m)
    return ind


def cx_arithmetic(
    children: list[Individual],
    parents: Sequence[Individual],
    rng: np.random.Generator | int | None,
    rate: float = 0.4,
    controller: bool = True,
    materials: bool = False,
    brain: bool = False,
) -> list[Individual]:
    """Arithmetic crossover of the real-valued genes (§3.1, §3.2), in place.

    ``children`` is shuffled; the first ``floor(rate * len(parents))`` of
    them take, for the controller, each gene's mean over two distinct random
    parents, and for each evolvable material (6, 7, 8; 9 follows 8), its
    properties' mean over another two distinct random parents; with
    ``brain``, the mean of the brain weights of another two (parents of one
    run share one :class:`~softgym.design.brain.BrainSpec`).

    Returns
    -------
    list of Individual
        The shuffled children.
    """
    rng = _rng(rng)
    order = rng.permutation(len(children))
    children[:] = [children[i] for i in order]
    n_cx = min(len(children), int(math.floor(rate * len(parents) + 1e-9)))
    if len(parents) < 2:
        return children
    for child in children[:n_cx]:
        if controller:
            a, b = rng.choice(len(parents), size=2, replace=False)
            pa, pb = parents[int(a)].controller, parents[int(b)].controller
            child.controller = Controller.clipped(
                temp_amplitude=(pa.temp_amplitude + pb.temp_amplitude) / 2.0,
                period=(pa.period + pb.period) / 2.0,
                muscle_cte=(pa.muscle_cte + pb.muscle_cte) / 2.0,
            )
        if materials:
            for row in range(3):
                a, b = rng.choice(len(parents), size=2, replace=False)
                child.materials[row] = (
                    parents[int(a)].materials[row] + parents[int(b)].materials[row]
                ) / 2.0
            set_counterphase(child.materials)
        if brain:
            a, b = rng.choice(len(parents), size=2, replace=False)
            wa, wb = parents[int(a)].brain, parents[int(b)].brain
            if wa is not None and wb is not None:
                child.brain = np.clip((wa + wb) / 2.0, -WEIGHT_BOUND, WEIGHT_BOUND)
    return children


def make_children(
    parents: Sequence[Individual],
    rng: np.random.Generator | int | None,
    next_id: Callable[[], int],
    *,
    shape: Sequence[int] = (6, 6, 6),
    rules: CompositionRules | None = None,
    evolve_controller: bool = False,
    evolve_materials: bool = False,
    crossover_rate: float = 0.4,
    max_attempts: int = 1500,
    evolve_brain: bool = False,
    evolve_body: bool = True,
) -> list[Individual]:
    """One generation's variation (§2.5, §3.1, §3.2).

    Parents are shuffled; each makes one child (a copy with a new id and the
    parent's age) whose CPPN is mutated with validity retries (unless
    ``evolve_body`` is False: a fixed body). Then, if the controller,
    materials or brain evolve, arithmetic crossover on
    ``floor(crossover_rate * len(parents))`` children and bounded Gaussian
    mutation of every child (controller, materials, then brain weights).

    Parameters
    ----------
    parents : sequence of Individual
        The current population (ages already incremented).
    rng : numpy.random.Generator
    next_id : callable
        Returns a fresh id on each call.

    Returns
    -------
    list of Individual
        ``len(parents)`` children, not yet evaluated.
    """
    rng = _rng(rng)
    order = rng.permutation(len(parents))
    children = []
    for i in order:
        child = parents[int(i)].child(next_id())
        if evolve_body:
            mut_cppn(child, rng, shape=shape, rules=rules, max_attempts=max_attempts)
        children.append(child)
    if evolve_controller or evolve_materials or evolve_brain:
        cx_arithmetic(
            children,
            parents,
            rng,
            rate=crossover_rate,
            controller=evolve_controller,
            materials=evolve_materials,
            brain=evolve_brain,
        )
        for child in children:
            if evolve_controller:
                mut_controller(child, rng)
            if evolve_materials:
                mut_materials(child, rng)
            if evolve_brain:
                mut_brain(child, rng)
    return children

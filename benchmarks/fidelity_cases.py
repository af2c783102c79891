"""The case set of the seed-engine fidelity benchmark (issue 16, point 4).

The protocol's vocabulary (regimes, cases read from stored data, perturbations) is
:mod:`softgym.fidelity`, re-exported here; this file adds the generation of the three
case sets (the random bodies need ``evolvers``).

Deterministic definitions of every robot, actuation regime and perturbation that
``benchmarks/data/seed_engine/make_oracle_data.py`` ran on the seed's own engine
(the oracle) and that ``benchmarks/fidelity_seed.py`` runs in softgym. Importable
without ``../shared``::

    import sys; sys.path.insert(0, "benchmarks")
    from fidelity_cases import REGIMES, all_cases, case_design, perturbed_voxel

    for case in all_cases():                       # structured, random, fence
        for regime in REGIMES:                     # "gentle", "medium", "strong"
            for draw in range(7):                  # 0 = unperturbed, 1..6 perturbed
                design = case_design(case, regime, draw)
                voxel = perturbed_voxel(case, draw)    # (i, j, k) or None
                terrain = case.terrain             # "flat" or "fence"

Sets
----
* :func:`structured_bodies`: hand-made bodies (cubes of one material, half/half
  blocks, layers, checkerboards, legged bodies, L-shapes, bars, with and without
  bone; many mirror-symmetric).
* :func:`random_bodies`: bodies of softgym's seed-style random CPPN genomes
  (``evolvers.operators.genome.Individual.random``), some filtered to contain bone, some drawn
  under the obstacle experiment's rules (>= 1 bone voxel), some mutated a few times
  with ``evolvers.operators.variation.mut_cppn``.
* :func:`fence_cases`: 6x6x6 bodies on the seed's fence task (a 1-voxel-high,
  1-voxel-thick square wall with a 10x10 interior, 2 voxels from the robot on every
  side; the seed study).

Perturbation
------------
Draw ``k > 0`` multiplies the density of ONE robot voxel by ``1 + 1e-6``
(:data:`PERTURBATION`): that voxel gets a new palette id (``max id + 1``, i.e. 10 for
the seed palette) holding a copy of its material with the density changed. The voxel
is the ``k``-th entry of a permutation of the filled voxels seeded by the case name,
so draws 1..6 perturb six different voxels. Apply the controller before the
perturbation (:func:`case_design` does): the copy carries the muscle CTE of the
material it copies, and :class:`~softgym.design.RobotDesign` re-syncs only ids 3
and 4 when the controller changes.

Stored designs
--------------
The oracle data files store every case's grid, so a change of the CPPN code that
changes what :func:`random_bodies` draws is detected (:func:`check_grid`) rather than
silently comparing different robots.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

import numpy as np

from softgym.design.material import default_palette
from softgym.design.robot import RobotDesign
from softgym.fidelity import (
    FENCE,
    PERTURBATION,
    REGIMES,
    SIM_SETTINGS,
    Case,
    case_design,
    cases_from_data,
    check_grid,
    controller,
    perturb,
    perturbed_voxel,
)

__all__ = [
    "FENCE",
    "PERTURBATION",
    "REGIMES",
    "SIM_SETTINGS",
    "Case",
    "all_cases",
    "case_design",
    "case_sets",
    "cases_from_data",
    "check_grid",
    "controller",
    "fence_cases",
    "perturb",
    "perturbed_voxel",
    "random_bodies",
    "structured_bodies",
]

# --------------------------------------------------------------------------------------------
# Helpers
# --------------------------------------------------------------------------------------------

SOFT, BONE, PLUS, MINUS = 1, 2, 3, 4


def _meta(design: RobotDesign, **extra: Any) -> dict[str, Any]:
    g = design.grid
    mass = float(sum(design.palette[int(v)].density for v in g[g != 0].ravel())) * 1e-6
    return dict(
        n_voxels=design.n_voxels,
        has_bone=bool((g == BONE).any()),
        robot_mass_kg=mass,
        mirror_x=bool(np.array_equal(g, g[::-1])),
        mirror_y=bool(np.array_equal(g, g[:, ::-1])),
        materials={str(k): v for k, v in design.material_counts().items()},
        **extra,
    )


def _case(
    name: str, set_: str, grid: np.ndarray, desc: str = "", terrain: str = "flat", **extra: Any
) -> Case:
    design = RobotDesign(np.asarray(grid, dtype=np.int8))
    if not design.is_connected():
        raise AssertionError(f"case {name} is not one connected body")
    meta = _meta(design, **extra)
    if desc:
        meta["description"] = desc
    return Case(name, set_, design, terrain, meta)


def _full(shape: tuple[int, int, int], mid: int) -> np.ndarray:
    return np.full(shape, mid, dtype=np.int8)


# --------------------------------------------------------------------------------------------
# Structured bodies
# --------------------------------------------------------------------------------------------


def _structured_grids() -> list[tuple[str, np.ndarray, str]]:
    S6 = (6, 6, 6)
    out: list[tuple[str, np.ndarray, str]] = []

    def add(name: str, grid: np.ndarray, desc: str) -> None:
        out.append((name, grid, desc))

    add("cube_active_plus", _full(S6, PLUS), "6x6x6 Active_+")
    add("cube_active_minus", _full(S6, MINUS), "6x6x6 Active_-")
    add("cube_passive_soft", _full(S6, SOFT), "6x6x6 Passive_Soft (no actuation: must stay put)")

    g = _full(S6, SOFT)
    g[:3] = PLUS
    add("half_x_plus_soft", g, "x < 3 Active_+, rest Passive_Soft")
    g = _full(S6, SOFT)
    g[:3] = MINUS
    add("half_x_minus_soft", g, "x < 3 Active_-, rest Passive_Soft")
    g = _full(S6, MINUS)
    g[:3] = PLUS
    add("half_x_plus_minus", g, "x < 3 Active_+, rest Active_-")
    g = _full(S6, MINUS)
    g[:, :, :3] = PLUS
    add("half_z_plus_minus", g, "z < 3 Active_+, z >= 3 Active_- (layered)")
    g = _full(S6, SOFT)
    g[:, :, 3:] = PLUS
    add("half_z_soft_plus", g, "z < 3 Passive_Soft, z >= 3 Active_+")

    g = np.empty(S6, dtype=np.int8)
    for z in range(6):
        g[:, :, z] = (PLUS, MINUS, SOFT)[z % 3]
    add("layers_z_pms", g, "z layers Active_+, Active_-, Passive_Soft, repeated")
    g = np.empty(S6, dtype=np.int8)
    for x in range(6):
        g[x] = PLUS if x % 2 == 0 else MINUS
    add("stripes_x_pm", g, "x slices alternating Active_+ / Active_-")

    i, j, k = np.indices(S6)
    add(
        "checker_1",
        np.where((i + j + k) % 2 == 0, PLUS, MINUS).astype(np.int8),
        "3-D checkerboard of single voxels, Active_+ / Active_-",
    )
    add(
        "checker_2",
        np.where((i // 2 + j // 2 + k // 2) % 2 == 0, PLUS, SOFT).astype(np.int8),
        "3-D checkerboard of 2x2x2 blocks, Active_+ / Passive_Soft",
    )

    # legged bodies: a 2-layer deck on four 2x2 legs of height 4
    def quadruped(deck: int, front: int, back: int) -> np.ndarray:
        g = np.zeros(S6, dtype=np.int8)
        g[:, :, 4:] = deck
        for x0, leg in ((0, back), (4, front)):
            for y0 in (0, 4):
                g[x0 : x0 + 2, y0 : y0 + 2, :4] = leg
        return g

    add(
        "quadruped_soft",
        quadruped(SOFT, PLUS, MINUS),
        "soft deck (z 4-5), front legs (x 4-5) Active_+, back legs Active_-",
    )
    add(
        "quadruped_same",
        quadruped(SOFT, PLUS, PLUS),
        "soft deck, four Active_+ legs (mirror-symmetric)",
    )
    add(
        "quadruped_bone",
        quadruped(BONE, PLUS, MINUS),
        "bone deck, front legs Active_+, back legs Active_-",
    )

    g = np.zeros(S6, dtype=np.int8)
    g[:, :, 3:] = SOFT
    g[0:2, :, :3] = PLUS
    g[4:6, :, :3] = MINUS
    add("biped_walls", g, "soft top half, two full-width legs (x 0-1 Active_+, x 4-5 Active_-)")

    g = np.zeros(S6, dtype=np.int8)
    g[:, :, :2] = MINUS
    g[:2, :, :] = PLUS
    add("l_shape", g, "L in the x-z plane: floor slab (z 0-1) Active_-, upright (x 0-1) Active_+")
    g = np.zeros(S6, dtype=np.int8)
    g[:, :, :2] = PLUS
    g[:2, :, 2:] = BONE
    add("l_shape_bone", g, "L: floor slab Active_+, upright of bone")
    g = np.zeros((6, 6, 2), dtype=np.int8)
    g[:, :2] = PLUS
    g[:2, :] = MINUS
    add("l_flat", g, "flat L (6x6x2) in the x-y plane: arm along x Active_+, arm along y Active_-")

    add("bar_x_plus", _full((6, 2, 2), PLUS), "6x2x2 bar of Active_+")
    g = _full((6, 2, 2), PLUS)
    g[3:] = MINUS
    add("bar_x_plus_minus", g, "6x2x2 bar, x < 3 Active_+, rest Active_-")
    g = _full((6, 3, 3), MINUS)
    g[:, 1, 1] = BONE
    add("bar_bone_spine", g, "6x3x3 Active_- bar with a bone spine along its axis")
    add("small_cube_plus", _full((2, 2, 2), PLUS), "2x2x2 Active_+")

    g = _full(S6, MINUS)
    g[2:4, 2:4, 2:4] = BONE
    add("cube_bone_core", g, "6x6x6 Active_- with a 2x2x2 bone core")
    g = _full(S6, BONE)
    g[:3] = PLUS
    add("half_x_plus_bone", g, "x < 3 Active_+, rest Passive_Hard")

    g = np.zeros(S6, dtype=np.int8)
    for z in range(3):
        g[z : 6 - z, z : 6 - z, 2 * z : 2 * z + 2] = (MINUS, PLUS, SOFT)[z]
    add("pyramid", g, "stepped pyramid: 6x6, 4x4, 2x2 slabs of Active_-, Active_+, Passive_Soft")
    g = np.zeros(S6, dtype=np.int8)
    for x in range(6):
        g[x, :, : x + 1] = PLUS if x < 3 else SOFT
    add("wedge", g, "wedge rising along x: x < 3 Active_+, rest Passive_Soft")
    g = _full(S6, PLUS)
    g[1:5, 1:5, 1:5] = 0
    add("shell_plus", g, "hollow 6x6x6 Active_+ shell, one voxel thick")
    g = np.zeros((6, 6, 2), dtype=np.int8)
    g[2:4, :, :] = PLUS
    g[:, 2:4, :] = MINUS
    add(
        "cross_flat",
        g,
        "flat plus sign (6x6x2): arm along y Active_+, arm along x Active_-, centre Active_-",
    )
    g = np.zeros(S6, dtype=np.int8)
    g[:, :, :2] = SOFT
    g[0:2, 0:2, 2:] = PLUS
    g[4:6, 2:4, 2:] = MINUS
    g[0:2, 4:6, 2:4] = PLUS
    add("tripod_asym", g, "soft base slab with three muscle towers of different heights")
    return out


def structured_bodies() -> list[Case]:
    """Hand-made bodies (6x6x6 or smaller), each a :class:`Case` of set ``"structured"``."""
    return [_case(name, "structured", g, desc) for name, g, desc in _structured_grids()]


# --------------------------------------------------------------------------------------------
# Random bodies (softgym's seed-style genomes)
# --------------------------------------------------------------------------------------------

#: Counts of the random set: plain seed-style draws, draws filtered to contain bone,
#: draws under the obstacle rules (>= 1 bone, >= 10 % tissue), mutated genomes.
RANDOM_COUNTS = dict(plain=30, bone=14, obstacle_rules=8, mutated=14)


def _random_individual(seed: tuple[int, ...], rules: Any = None):
    from evolvers.operators.genome import Individual

    return Individual.random(np.random.default_rng(list(seed)), id=int(seed[-1]), rules=rules)


def _random_case(name: str, set_: str, ind: Any, terrain: str = "flat", **extra: Any) -> Case:
    design = ind.design()
    if design.palette != default_palette():
        raise AssertionError(f"{name}: random genomes should draw with the default palette")
    meta = _meta(design, **extra)
    return Case(name, set_, design, terrain, meta)


def random_bodies() -> list[Case]:
    """Bodies of seed-style random CPPN genomes (:data:`RANDOM_COUNTS`), set ``"random"``.

    * ``rand_pNN``: ``Individual.random(default_rng([16, 1, NN]))`` under the seed's rules
      (>= 30 % filled, >= 10 % muscle); mostly without bone.
    * ``rand_bNN``: the first seed-style draws of ``default_rng([16, 2, i])``, i = 0, 1, ...,
      that contain bone (Passive_Hard).
    * ``rand_oNN``: draws under ``CompositionRules.obstacles()`` (>= 1 bone voxel).
    * ``rand_mNN_xK``: a seed-style draw of ``default_rng([16, 4, NN])`` mutated K = 1..5
      times by ``evolvers.operators.variation.mut_cppn`` with ``default_rng([16, 5, NN])``.
    """
    from evolvers.operators.variation import mut_cppn
    from softgym.design import CompositionRules

    cases = []
    for n in range(RANDOM_COUNTS["plain"]):
        ind = _random_individual((16, 1, n))
        cases.append(
            _random_case(
                f"rand_p{n:02d}", "random", ind, seed=[16, 1, n], rules="seed", mutations=0
            )
        )
    i = found = 0
    while found < RANDOM_COUNTS["bone"]:
        ind = _random_individual((16, 2, i))
        if (ind.grid() == BONE).any():
            cases.append(
                _random_case(
                    f"rand_b{found:02d}", "random", ind, seed=[16, 2, i], rules="seed", mutations=0
                )
            )
            found += 1
        i += 1
    for n in range(RANDOM_COUNTS["obstacle_rules"]):
        ind = _random_individual((16, 3, n), CompositionRules.obstacles())
        cases.append(
            _random_case(
                f"rand_o{n:02d}", "random", ind, seed=[16, 3, n], rules="obstacles", mutations=0
            )
        )
    for n in range(RANDOM_COUNTS["mutated"]):
        ind = _random_individual((16, 4, n))
        k = 1 + n % 5
        rng = np.random.default_rng([16, 5, n])
        done = sum(bool(mut_cppn(ind, rng)) for _ in range(k))
        cases.append(
            _random_case(
                f"rand_m{n:02d}_x{k}",
                "random",
                ind,
                seed=[16, 4, n],
                rules="seed",
                mutations=done,
                mutation_seed=[16, 5, n],
            )
        )
    return cases


# --------------------------------------------------------------------------------------------
# Fence cases
# --------------------------------------------------------------------------------------------

#: Structured 6x6x6 bodies that also run on the fence.
FENCE_STRUCTURED = (
    "cube_active_minus",
    "half_x_plus_soft",
    "quadruped_bone",
    "cube_bone_core",
    "half_x_plus_bone",
    "l_shape_bone",
)
#: Random genomes of the obstacle experiment (its composition rules) on the fence.
FENCE_RANDOM = 16


def fence_cases() -> list[Case]:
    """6x6x6 bodies on the seed's fence (:data:`FENCE`), set ``"fence"``.

    ``fence_<structured name>`` for :data:`FENCE_STRUCTURED`, and ``fence_oNN``:
    ``Individual.random(default_rng([16, 6, NN]), rules=CompositionRules.obstacles())``,
    the obstacle experiment's random individuals (all with bone).
    """
    from softgym.design import CompositionRules

    by_name = {c.name: c for c in structured_bodies()}
    cases = []
    for name in FENCE_STRUCTURED:
        c = by_name[name]
        if c.design.shape != (6, 6, 6):
            raise AssertionError(f"fence bodies must be 6x6x6, {name} is {c.design.shape}")
        cases.append(Case(f"fence_{name}", "fence", c.design, "fence", dict(c.meta, source=name)))
    for n in range(FENCE_RANDOM):
        ind = _random_individual((16, 6, n), CompositionRules.obstacles())
        cases.append(
            _random_case(
                f"fence_o{n:02d}",
                "fence",
                ind,
                terrain="fence",
                seed=[16, 6, n],
                rules="obstacles",
                mutations=0,
            )
        )
    return cases


# --------------------------------------------------------------------------------------------
# Held-out bodies
# --------------------------------------------------------------------------------------------

#: Counts of the held-out set: plain seed-style draws and draws that contain bone, from
#: seeds no other set uses (no formulation was tuned on them).
HELDOUT_COUNTS = dict(plain=64, bone=26)


def heldout_bodies() -> list[Case]:
    """Seed-style random CPPN bodies kept out of every tuning (:data:`HELDOUT_COUNTS`), set ``"heldout"``.

    * ``held_pNN``: ``Individual.random(default_rng([16, 7, NN]))`` under the seed's rules;
    * ``held_bNN``: the first draws of ``default_rng([16, 8, i])``, i = 0, 1, ..., that
      contain bone.

    They are the paired fidelity comparison's main sample (``benchmarks/fidelity_seed.py
    --paired``): a formulation change is judged on bodies it was not developed on.
    """
    cases = []
    for n in range(HELDOUT_COUNTS["plain"]):
        ind = _random_individual((16, 7, n))
        cases.append(
            _random_case(f"held_p{n:02d}", "heldout", ind, seed=[16, 7, n], rules="seed", mutations=0)
        )
    i = found = 0
    while found < HELDOUT_COUNTS["bone"]:
        ind = _random_individual((16, 8, i))
        if (ind.grid() == BONE).any():
            cases.append(
                _random_case(
                    f"held_b{found:02d}", "heldout", ind, seed=[16, 8, i], rules="seed", mutations=0
                )
            )
            found += 1
        i += 1
    return cases


def case_sets() -> dict[str, list[Case]]:
    """``{"structured": [...], "random": [...], "fence": [...], "heldout": [...]}``."""
    return {
        "structured": structured_bodies(),
        "random": random_bodies(),
        "fence": fence_cases(),
        "heldout": heldout_bodies(),
    }


def all_cases(sets: Iterable[str] = ("structured", "random", "fence")) -> list[Case]:
    """Every case of the named sets, in a fixed order."""
    table = case_sets()
    return [c for s in sets for c in table[s]]

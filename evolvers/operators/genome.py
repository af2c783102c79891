"""`Individual`: a CPPN genome, material genes, controller genes, age and lineage.

The genome of the seed study (docs/PHYSICS.md):

* a :class:`~softgym.design.CPPN` drawing the voxel grid and choosing materials;
* material genes: Young's modulus (Pa), density (kg/m^3) and CTE (1/°C) of
  the evolvable materials 6-9 (material 9 is the counter-phase copy of 8);
* controller genes: a :class:`~softgym.design.Controller` (temperature
  amplitude, period, muscle CTE);
* optionally a network controller: ``brain``, the flat weight vector of a
  :class:`~softgym.design.brain.BrainSpec` (``brain_spec``), run in closed loop;
* optionally a fixed ``body`` (a :class:`~softgym.design.RobotDesign` whose
  grid and palette every robot of the run shares; ``cppn`` is then None and
  only the controller / brain genes vary: "brain only on a fixed body");
* bookkeeping: ``age`` (generations survived, the age objective), ``id``
  (unique in a run, increasing) and ``parent_id``.

Evaluation results live on the individual too (``objectives``, ``trace``,
``novelty``) so selection reads them directly.
"""

from __future__ import annotations

import hashlib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from softgym.design import CPPN, MATERIAL_TREE_4, CompositionRules, Controller, default_palette
from softgym.design.brain import BrainSpec
from softgym.design.robot import RobotDesign
from softgym.exceptions import InvalidParameterError
from softgym.validate import show

__all__ = [
    "INITIAL_MATERIAL_GENES",
    "MATERIAL_GENE_IDS",
    "Individual",
]

#: Material ids whose properties are genes (rows of ``Individual.materials``).
MATERIAL_GENE_IDS: tuple[int, ...] = (6, 7, 8, 9)
#: Initial material genes (the seed study): rows ids 6-9, columns (E Pa, density kg/m^3, CTE 1/°C).
INITIAL_MATERIAL_GENES = np.array(
    [
        [5e6, 1e6, 0.0],
        [5e8, 1e6, 0.0],
        [5e6, 1e6, 0.05],
        [5e6, 1e6, -0.05],
    ]
)
INITIAL_MATERIAL_GENES.setflags(write=False)


@dataclass(eq=False)
class Individual:
    """One robot genome of an evolutionary run.

    Parameters
    ----------
    cppn : CPPN or None
        Body and material-choice genome (None with a fixed ``body``).
    materials : ndarray of shape (4, 3), float64
        Genes of materials 6, 7, 8, 9: columns Young's modulus (Pa),
        density (kg/m^3), CTE (1/°C).
    controller : Controller
        Controller genes.
    id : int
        Unique id in the run (newer individuals have larger ids).
    parent_id : int or None
        Id of the parent (None for random individuals).
    age : int
        Generations of ancestry (the seed increments every individual's age
        each generation; children inherit it; random newcomers start at 0).
    objectives : dict of str to float
        Evaluation results by metric name (filled by the evaluator).
    trace : ndarray of shape (n_points, 4), optional
        Centre-of-mass trace (x, y, z, t) in m and s, for novelty.
    novelty : float, optional
        Last novelty score (lower = more novel).
    brain : ndarray of shape (brain_spec.n_params,), float64, optional
        Weights of a network controller (None: the open-loop sinusoid alone).
    brain_spec : BrainSpec, optional
        What ``brain`` is read as (required with ``brain``).
    body : RobotDesign, optional
        A fixed body: its grid and palette replace the CPPN's and the material
        genes (its own brain, if any, is ignored).
    """

    cppn: CPPN | None
    materials: np.ndarray = field(default_factory=lambda: INITIAL_MATERIAL_GENES.copy())
    controller: Controller = field(default_factory=Controller)
    id: int = 0
    parent_id: int | None = None
    age: int = 0
    objectives: dict[str, float] = field(default_factory=dict)
    trace: np.ndarray | None = None
    novelty: float | None = None
    brain: np.ndarray | None = None
    brain_spec: BrainSpec | None = None
    body: RobotDesign | None = None
    _grid: np.ndarray | None = field(default=None, repr=False)
    _grid_shape: tuple[int, ...] | None = field(default=None, repr=False)

    def __post_init__(self) -> None:
        self.materials = np.array(self.materials, dtype=np.float64).reshape(4, 3)
        if self.brain is not None:
            if self.brain_spec is None:
                raise InvalidParameterError("an individual with a brain needs its brain_spec")
            self.brain = np.array(self.brain, dtype=np.float64).reshape(self.brain_spec.n_params)
        if self.cppn is None and self.body is None:
            raise InvalidParameterError("an individual needs a cppn or a fixed body")

    # ------------------------------------------------------------------ phenotype
    @classmethod
    def random(
        cls,
        rng: np.random.Generator,
        id: int,
        shape: Sequence[int] = (6, 6, 6),
        outputs: Sequence[str] = MATERIAL_TREE_4,
        rules: CompositionRules | None = None,
        *,
        brain_spec: BrainSpec | None = None,
        body: RobotDesign | None = None,
    ) -> Individual:
        """A random valid individual (the seed's new and gen-0 individuals).

        Parameters
        ----------
        rng : numpy.random.Generator
        id : int
        shape : (nx, ny, nz)
            Grid the CPPN draws in.
        outputs : sequence of str
            CPPN outputs (:data:`~softgym.design.MATERIAL_TREE_4` or ``_8``).
        rules : CompositionRules, optional
            Validity (default :meth:`CompositionRules.seed`).
        brain_spec : BrainSpec, optional
            Draw a brain too (``brain_spec.random(rng)``, after the CPPN).
        body : RobotDesign, optional
            A fixed body: no CPPN is drawn; the controller starts as the body's.

        Without ``brain_spec`` and ``body`` the draws are the seed's (bit-identical).
        """
        if body is None:
            rules = CompositionRules.seed() if rules is None else rules
            g = CPPN.random_valid(outputs, rng=rng, shape=tuple(shape), is_valid=rules)
            ind = cls(cppn=g, id=int(id))
        else:
            ind = cls(cppn=None, controller=body.controller, id=int(id), body=body)
        if brain_spec is not None:
            ind.brain = np.array(brain_spec.random(rng).weights)
            ind.brain_spec = brain_spec
        return ind

    def grid(self, shape: Sequence[int] = (6, 6, 6)) -> np.ndarray:
        """The material grid, ndarray of shape ``shape``, int8 (cached)."""
        shape = tuple(int(s) for s in shape)
        if self.body is not None:
            return self.body.grid
        if self._grid is None or self._grid_shape != shape:
            self._grid = self.cppn.to_grid(shape)
            self._grid_shape = shape
        return self._grid

    def palette(self):
        """The default palette with materials 6-9 set from the material genes (a fixed body's own)."""
        if self.body is not None:
            return self.body.palette
        pal = default_palette()
        for row, mid in zip(self.materials, MATERIAL_GENE_IDS):
            pal = pal.with_changes(
                mid, youngs_modulus=float(row[0]), density=float(row[1]), cte=float(row[2])
            )
        return pal

    def design(self, shape: Sequence[int] = (6, 6, 6)) -> RobotDesign:
        """The :class:`~softgym.design.RobotDesign` of this genome (not validated; with its brain)."""
        brain = None if self.brain is None else self.brain_spec.clipped(self.brain)
        return RobotDesign(
            self.grid(shape), palette=self.palette(), controller=self.controller, brain=brain
        )

    def phenotype_key(self, shape: Sequence[int] = (6, 6, 6)) -> str:
        """Hash of what the simulator sees: grid, used materials' properties, controller, brain.

        Two individuals with the same key behave identically, so the second
        is not simulated again (the seed's md5 phenotype cache, §2.3).
        """
        grid = self.grid(shape)
        h = hashlib.sha256()
        h.update(repr(grid.shape).encode())
        h.update(np.ascontiguousarray(grid).tobytes())
        used = sorted(int(v) for v in np.unique(grid) if v)
        pal = self.palette()
        c = self.controller
        for mid in used:
            m = pal[mid]
            h.update(
                repr(
                    (mid, m.youngs_modulus, m.density, m.poisson, m.cte, m.mu_static, m.mu_kinetic)
                ).encode()
            )
        h.update(repr((c.temp_amplitude, c.period, c.muscle_cte)).encode())
        if self.brain is not None:  # (sinusoid keys are unchanged: old caches stay valid)
            h.update(repr(sorted(self.brain_spec.to_dict().items())).encode())
            h.update(np.ascontiguousarray(self.brain, dtype=np.float64).tobytes())
        return h.hexdigest()

    # ------------------------------------------------------------------ copies
    def child(self, id: int) -> Individual:
        """A copy with a new ``id``, this individual as parent, no evaluation results."""
        return Individual(**self._child_fields(id))

    def _child_fields(self, id: int) -> dict[str, Any]:
        """The constructor keywords of :meth:`child` (for subclasses: DEAP's ``Softbot``)."""
        return {
            "cppn": None if self.cppn is None else self.cppn.copy(),
            "materials": self.materials.copy(),
            "controller": self.controller,
            "id": int(id),
            "parent_id": self.id,
            "age": self.age,
            "brain": None if self.brain is None else self.brain.copy(),
            "brain_spec": self.brain_spec,
            "body": self.body,
        }

    def value(self, name: str) -> float:
        """An objective's value (``"age"`` reads the age)."""
        if name == "age":
            return float(self.age)
        return float(self.objectives[name])

    def genes(self) -> dict[str, float]:
        """The real-valued genes as flat named values (log columns, study reports).

        Returns
        -------
        dict of str to float
            ``temp_amplitude`` (°C), ``period`` (s), ``muscle_cte`` (1/°C) of the
            controller, and ``m{id}_youngs_modulus`` (Pa), ``m{id}_density``
            (kg/m^3), ``m{id}_cte`` (1/°C) of each evolvable material id 6-9.
        """
        c = self.controller
        out = {
            "temp_amplitude": float(c.temp_amplitude),
            "period": float(c.period),
            "muscle_cte": float(c.muscle_cte),
        }
        for mid, row in zip(MATERIAL_GENE_IDS, self.materials):
            for name, v in zip(("youngs_modulus", "density", "cte"), row):
                out[f"m{mid}_{name}"] = float(v)
        return out

    # ------------------------------------------------------------------ JSON
    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict (the trace is stored separately, in checkpoint arrays)."""
        out = {
            "id": self.id,
            "parent_id": self.parent_id,
            "age": self.age,
            "cppn": None if self.cppn is None else self.cppn.to_dict(),
            "materials": self.materials.tolist(),
            "controller": self.controller.to_dict(),
            "objectives": dict(self.objectives),
            "novelty": self.novelty,
        }
        # only when present: a sinusoid individual's dict is what it has always been
        if self.brain is not None:
            out["brain"] = {**self.brain_spec.to_dict(), "weights": [float(v) for v in self.brain]}
        if self.body is not None:
            out["body"] = self.body.replace(brain=None).to_dict()
        return out

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Individual:
        """Inverse of :meth:`to_dict` (dicts without ``brain`` / ``body`` load with None).

        Raises
        ------
        InvalidParameterError
            Naming the key, if ``data`` is not an individual's record.
        """
        if not isinstance(data, Mapping):
            raise InvalidParameterError(f"an individual must be an object, got {show(data)}")
        try:
            return cls._from_record(data)
        except KeyError as exc:
            raise InvalidParameterError(f"individual: the key {exc.args[0]!r} is missing") from None
        except (TypeError, ValueError, AttributeError, IndexError, OverflowError) as exc:
            raise InvalidParameterError(f"individual: a malformed key ({exc!s:.160})") from None

    @classmethod
    def _from_record(cls, data: Mapping[str, Any]) -> Individual:
        brain = data.get("brain")
        spec = None
        if brain is not None:
            spec = BrainSpec.from_dict({k: v for k, v in brain.items() if k != "weights"})
        body = data.get("body")
        return cls(
            cppn=None if data.get("cppn") is None else CPPN.from_dict(data["cppn"]),
            materials=np.asarray(data["materials"], dtype=np.float64),
            controller=Controller.from_dict(data["controller"]),
            id=int(data["id"]),
            parent_id=None if data.get("parent_id") is None else int(data["parent_id"]),
            age=int(data["age"]),
            objectives={k: float(v) for k, v in data.get("objectives", {}).items()},
            novelty=None if data.get("novelty") is None else float(data["novelty"]),
            brain=None if brain is None else np.asarray(brain["weights"], dtype=np.float64),
            brain_spec=spec,
            body=None if body is None else RobotDesign.from_dict(body),
        )

"""Materials and palettes.

A :class:`Material` is one row of physical properties; a :class:`Palette` maps
material ids (the integers stored in a design's voxel grid) to materials.

Material ids follow the seed study (Ev-SoftBots / evosoro), so the seed's
CPPN material trees and ``.vxa`` files carry over unchanged:

====  ==================  ===========  ==========  ============================
 id   name                E (Pa)       CTE (1/°C)  role
====  ==================  ===========  ==========  ============================
 0    (empty)             -            -           no voxel
 1    Passive_Soft        5e6          0           soft tissue ("fat")
 2    Passive_Hard        5e8          0           hard tissue ("bone")
 3    Active_+            5e6          +0.01       muscle, contracts when T < 0
 4    Active_-            5e6          -0.01       muscle, counter-phase of 3
 5    Obstacle            5e9          0           fixed wall voxels
 6    New_Passive_Soft    5e6          0           evolvable soft tissue
 7    New_Passive_Hard    5e8          0           evolvable hard tissue
 8    New_Active_+        5e6          +0.05       evolvable muscle
 9    New_Active_-        5e6          -0.05       counter-phase copy of 8
====  ==================  ===========  ==========  ============================

All have density 1e6 kg/m^3, Poisson's ratio 0.35, static friction 1 and
kinetic friction 0.5 (docs/PHYSICS.md).
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, fields, replace
from functools import lru_cache
from typing import Any

import numpy as np

from softgym.engine.config import DENSITY_RANGE, YOUNGS_MODULUS_RANGE
from softgym.exceptions import InvalidDesignError, InvalidParameterError
from softgym.validate import is_int, number

__all__ = [
    "BONE_IDS",
    "EVOLVABLE_BOUNDS",
    "MAX_ABS_CTE",
    "MAX_MATERIAL_ID",
    "MUSCLE_IDS",
    "OBSTACLE_IDS",
    "OLD_MATERIAL_IDS",
    "TISSUE_IDS",
    "Material",
    "MaterialBounds",
    "Palette",
    "default_palette",
    "seed_materials",
]

#: Largest material id a design grid (int8) can hold.
MAX_MATERIAL_ID = 127

#: Largest ``|CTE|`` (1/°C) a material may have. Twice the seed's largest (0.05, material 8):
#: at the controller's largest amplitude (20 °C) a voxel's rest size stays within
#: ``L (1 +- 2)``. Larger values only make runaway actuation.
MAX_ABS_CTE = 0.1

#: Ids of muscle materials in the seed palette (Active_+, Active_-, New_Active_+, New_Active_-).
MUSCLE_IDS: tuple[int, ...] = (3, 4, 8, 9)
#: Ids of passive tissue (soft and hard, old and new).
TISSUE_IDS: tuple[int, ...] = (1, 2, 6, 7)
#: Ids counted as "bone" by the obstacle experiment's rule (the seed study): Passive_Hard only.
BONE_IDS: tuple[int, ...] = (2,)
#: The seed's four original materials (the ``old_materials`` objective, §3.1).
OLD_MATERIAL_IDS: tuple[int, ...] = (1, 2, 3, 4)
#: Ids that are environment, not robot (not counted as robot voxels).
OBSTACLE_IDS: tuple[int, ...] = (5,)


@dataclass(frozen=True)
class Material:
    """Physical properties of one voxel material.

    Construction checks physical validity (real numbers, not bools or
    strings; positive modulus and density, Poisson's ratio in [0, 0.5),
    ``|CTE| <= 0.1`` 1/°C, non-negative friction, colour channels in [0, 1])
    and raises :class:`~softgym.exceptions.InvalidParameterError`
    otherwise. The evolutionary bounds of the materials GA are separate
    (:class:`MaterialBounds`).

    Parameters
    ----------
    name : str
        Display name (the ``<Name>`` of a ``.vxa`` palette entry).
    youngs_modulus : float
        Young's modulus E (Pa), > 0.
    density : float
        Density rho (kg/m^3), > 0.
    poisson : float
        Poisson's ratio, in [0, 0.5).
    cte : float
        Coefficient of thermal expansion (1/°C), in [-MAX_ABS_CTE, MAX_ABS_CTE]
        (``MAX_ABS_CTE`` = 0.1); 0 for passive tissue, the sign selects the
        phase of a muscle.
    mu_static, mu_kinetic : float
        Coulomb friction coefficients against the floor, >= 0.
    color : tuple of 3 or 4 floats
        RGB(A) display colour, each channel in [0, 1]; alpha defaults to 1.
    """

    name: str
    youngs_modulus: float
    density: float = 1e6
    poisson: float = 0.35
    cte: float = 0.0
    mu_static: float = 1.0
    mu_kinetic: float = 0.5
    color: tuple[float, ...] = (0.5, 0.5, 0.5, 1.0)

    def __post_init__(self) -> None:
        if not isinstance(self.name, str):
            raise InvalidParameterError(f"material name must be a str, got {self.name!r}")
        label = f"material {self.name!r}"
        E = number(f"{label}: youngs_modulus", self.youngs_modulus)
        rho = number(f"{label}: density", self.density)
        nu = number(f"{label}: poisson", self.poisson)
        cte = number(f"{label}: cte", self.cte)
        mus = number(f"{label}: mu_static", self.mu_static)
        muk = number(f"{label}: mu_kinetic", self.mu_kinetic)
        lo, hi = YOUNGS_MODULUS_RANGE
        if not lo <= E <= hi:
            raise InvalidParameterError(
                f"{label}: youngs_modulus must lie in [{lo:g}, {hi:g}] Pa, got {E:g}"
            )
        lo, hi = DENSITY_RANGE
        if not lo <= rho <= hi:
            raise InvalidParameterError(
                f"{label}: density must lie in [{lo:g}, {hi:g}] kg/m^3, got {rho:g}"
            )
        if not 0.0 <= nu < 0.5:
            raise InvalidParameterError(f"{label}: poisson must lie in [0, 0.5), got {nu}")
        if abs(cte) > MAX_ABS_CTE:
            raise InvalidParameterError(
                f"{label}: cte must lie in [-{MAX_ABS_CTE}, {MAX_ABS_CTE}] 1/degC, got {cte}"
            )
        if mus < 0 or muk < 0:
            raise InvalidParameterError(
                f"{label}: friction coefficients must be >= 0, got mu_static={mus}, mu_kinetic={muk}"
            )
        raw_color = self.color
        if isinstance(raw_color, (str, bytes)) or not isinstance(
            raw_color, (tuple, list, np.ndarray)
        ):
            raise InvalidParameterError(
                f"{label}: color must be a sequence of 3 or 4 numbers in [0, 1], got {raw_color!r}"
            )
        if len(raw_color) not in (3, 4):
            raise InvalidParameterError(
                f"{label}: color must be 3 or 4 numbers in [0, 1], got {len(raw_color)} values"
            )
        color = tuple(number(f"{label}: color channel", c) for c in raw_color)
        if len(color) == 3:
            color = (*color, 1.0)
        if len(color) != 4 or not all(math.isfinite(c) and 0.0 <= c <= 1.0 for c in color):
            raise InvalidParameterError(
                f"{label}: color must be 3 or 4 numbers in [0, 1], got {self.color!r}"
            )
        for name, value in (
            ("youngs_modulus", E),
            ("density", rho),
            ("poisson", nu),
            ("cte", cte),
            ("mu_static", mus),
            ("mu_kinetic", muk),
            ("color", color),
        ):
            object.__setattr__(self, name, value)

    @property
    def is_active(self) -> bool:
        """Whether the material is actuated (non-zero CTE)."""
        return self.cte != 0.0

    def replace(self, **changes: Any) -> Material:
        """Return a copy with some fields changed (validated again)."""
        return replace(self, **changes)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict of the fields."""
        out: dict[str, Any] = {f.name: getattr(self, f.name) for f in fields(self)}
        out["color"] = list(self.color)
        return out

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Material:
        """Inverse of :meth:`to_dict`; unknown keys raise :class:`InvalidDesignError`.

        Values out of range raise :class:`InvalidParameterError` (as the constructor does).
        """
        if not isinstance(data, Mapping):
            raise InvalidDesignError(f"a material must be an object, got {type(data).__name__}")
        known = {f.name for f in fields(cls)}
        unknown = set(data) - known
        if unknown:
            raise InvalidDesignError(f"unknown material field(s) {sorted(map(str, unknown))}")
        if "name" not in data or "youngs_modulus" not in data:
            raise InvalidDesignError("a material needs at least 'name' and 'youngs_modulus'")
        return cls(**dict(data))


@dataclass(frozen=True)
class MaterialBounds:
    """Bounds of the materials GA (the seed study).

    Parameters
    ----------
    youngs_modulus : (float, float)
        Range of E (Pa) for evolvable tissue.
    density : (float, float)
        Range of density (kg/m^3).
    cte_magnitude : (float, float)
        Range of ``|CTE|`` (1/°C) for evolvable muscle; tissue keeps CTE 0.
    """

    youngs_modulus: tuple[float, float] = (5e6, 5e8)
    density: tuple[float, float] = (1e3, 1e7)
    cte_magnitude: tuple[float, float] = (0.001, 0.04)

    def clip(self, material: Material) -> Material:
        """Clip E and density into range, and ``|CTE|`` if the material is active.

        The sign of the CTE is kept; a passive material (CTE 0) stays passive.
        """
        lo, hi = self.cte_magnitude
        cte = material.cte
        if cte != 0.0:
            cte = math.copysign(min(max(abs(cte), lo), hi), cte)
        return material.replace(
            youngs_modulus=min(
                max(material.youngs_modulus, self.youngs_modulus[0]), self.youngs_modulus[1]
            ),
            density=min(max(material.density, self.density[0]), self.density[1]),
            cte=cte,
        )

    def check(self, material: Material) -> None:
        """Raise :class:`InvalidParameterError` naming the property out of bounds."""
        checks = [
            ("youngs_modulus", material.youngs_modulus, self.youngs_modulus, "Pa"),
            ("density", material.density, self.density, "kg/m^3"),
        ]
        if material.cte != 0.0:
            checks.append(("|cte|", abs(material.cte), self.cte_magnitude, "1/degC"))
        for name, value, (lo, hi), unit in checks:
            if not lo <= value <= hi:
                raise InvalidParameterError(
                    f"material {material.name!r}: {name} = {value} {unit} is outside [{lo}, {hi}]"
                )


#: Bounds of the seed's materials GA.
EVOLVABLE_BOUNDS = MaterialBounds()


def seed_materials() -> dict[int, Material]:
    """The seed's materials by id: the four evosoro ones, the obstacle, the four evolvable ones.

    Returns
    -------
    dict of int to Material
        Ids 1-9 with the values of docs/PHYSICS.md.
    """
    return {
        1: Material("Passive_Soft", 5e6, color=(0.0, 1.0, 1.0)),
        2: Material("Passive_Hard", 5e8, color=(0.0, 0.0, 1.0)),
        3: Material("Active_+", 5e6, cte=0.01, color=(1.0, 0.0, 0.0)),
        4: Material("Active_-", 5e6, cte=-0.01, color=(0.0, 1.0, 0.0)),
        5: Material("Obstacle", 5e9, color=(1.0, 0.784, 0.0)),
        6: Material("New_Passive_Soft", 5e6, color=(0.6, 0.3, 0.0)),
        7: Material("New_Passive_Hard", 5e8, color=(0.3, 0.0, 0.0)),
        8: Material("New_Active_+", 5e6, cte=0.05, color=(1.0, 1.0, 0.0)),
        9: Material("New_Active_-", 5e6, cte=-0.05, color=(1.0, 0.5, 0.0)),
    }


class Palette(Mapping[int, Material]):
    """An immutable mapping from material id (1..127) to :class:`Material`.

    Id 0 always means "empty voxel" and is never a key. ``palette[k]`` is the
    material of grid value ``k``; iteration yields the ids in increasing order.

    Parameters
    ----------
    materials : mapping of int to Material, or sequence of Material
        A mapping gives the ids explicitly; a sequence assigns ids 1, 2, ...
        in order (``materials[k - 1]`` becomes id ``k``).
    """

    __slots__ = ("_ids", "_materials")

    def __init__(
        self, materials: Mapping[int, Material] | list[Material] | tuple[Material, ...]
    ) -> None:
        if isinstance(materials, Mapping):
            items = list(materials.items())
        elif isinstance(materials, (list, tuple)):
            items = list(enumerate(materials, start=1))
        else:
            raise InvalidDesignError(
                "a palette takes a mapping of id to Material or a list of Materials, "
                f"got {type(materials).__name__}"
            )
        if not items:
            raise InvalidDesignError("a palette needs at least one material")
        table: dict[int, Material] = {}
        for key, mat in items:
            if not is_int(key) or not 1 <= key <= MAX_MATERIAL_ID:
                raise InvalidDesignError(
                    f"material ids must be integers in 1..{MAX_MATERIAL_ID} (0 is empty), got {key!r}"
                )
            if not isinstance(mat, Material):
                raise InvalidDesignError(f"palette entry {key} is not a Material: {mat!r}")
            table[int(key)] = mat
        self._ids = tuple(sorted(table))
        self._materials = {k: table[k] for k in self._ids}

    def __getitem__(self, key: int) -> Material:
        try:
            return self._materials[key]
        except (KeyError, TypeError):  # TypeError: an unhashable key is never an id
            raise KeyError(
                f"no material with id {key!r} in the palette (ids {list(self._ids)})"
            ) from None

    def __iter__(self) -> Iterator[int]:
        return iter(self._ids)

    def __len__(self) -> int:
        return len(self._ids)

    def __repr__(self) -> str:
        inner = ", ".join(f"{k}: {m.name}" for k, m in self._materials.items())
        return f"Palette({{{inner}}})"

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Palette):
            return NotImplemented
        return self._materials == other._materials

    def __hash__(self) -> int:
        return hash(tuple(self._materials.items()))

    @property
    def max_id(self) -> int:
        """Largest material id."""
        return self._ids[-1]

    def with_material(self, material_id: int, material: Material) -> Palette:
        """Return a palette with ``material_id`` set (added or replaced)."""
        table = dict(self._materials)
        table[material_id] = material
        return Palette(table)

    def with_changes(self, material_id: int, **changes: Any) -> Palette:
        """Return a palette where material ``material_id`` has some fields changed."""
        return self.with_material(material_id, self[material_id].replace(**changes))

    def with_counterphase(self, source: int = 8, target: int = 9) -> Palette:
        """Make ``target`` the counter-phase twin of ``source`` (the seed study).

        The target keeps its name and colour and takes the source's Young's
        modulus, density, Poisson's ratio and friction, with ``cte = -source.cte``.
        This is how the seed's materials GA sets material 9 from material 8.
        """
        src = self[source]
        tgt = self[target] if target in self else src.replace(name=f"{src.name}_counterphase")
        return self.with_material(
            target,
            tgt.replace(
                youngs_modulus=src.youngs_modulus,
                density=src.density,
                poisson=src.poisson,
                mu_static=src.mu_static,
                mu_kinetic=src.mu_kinetic,
                cte=-src.cte,
            ),
        )

    def ids_of(self, name: str) -> list[int]:
        """Ids of the materials called ``name``."""
        return [k for k, m in self._materials.items() if m.name == name]

    def to_list(self) -> list[dict[str, Any]]:
        """JSON-ready list of ``{"id": k, **material.to_dict()}``."""
        return [{"id": k, **m.to_dict()} for k, m in self._materials.items()]

    @classmethod
    def from_list(cls, items: list[Mapping[str, Any]]) -> Palette:
        """Inverse of :meth:`to_list`."""
        if not isinstance(items, list):
            raise InvalidDesignError(
                f"a palette must be a list of materials, got {type(items).__name__}"
            )
        table: dict[int, Material] = {}
        for i, item in enumerate(items):
            if not isinstance(item, Mapping) or "id" not in item:
                raise InvalidDesignError(f"palette entry {i} has no 'id'")
            data = dict(item)
            key = data.pop("id")
            if not is_int(key) or not 1 <= key <= MAX_MATERIAL_ID:
                raise InvalidDesignError(
                    f"palette entry {i}: 'id' must be an integer in 1..{MAX_MATERIAL_ID} "
                    f"(0 is empty), got {key!r}"
                )
            key = int(key)
            if key in table:
                raise InvalidDesignError(f"palette lists material id {key} twice")
            try:
                table[key] = Material.from_dict(data)
            except (InvalidParameterError, TypeError) as exc:
                raise InvalidDesignError(f"palette entry id {key}: {exc}") from exc
        return cls(table)


@lru_cache(maxsize=1)
def default_palette() -> Palette:
    """The default palette: the seed's materials 1-9 (see the module table).

    Palettes are immutable, so the same object is returned on every call.
    """
    return Palette(seed_materials())

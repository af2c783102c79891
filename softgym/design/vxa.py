"""Read and write the seed's ``.vxa`` files (VoxCAD / evosoro format).

What is read and written: the voxel structure, the material palette and the
thermal (controller) settings; export also writes the seed's simulator and
environment settings so the file opens and runs in VoxCAD / evosoro's
``voxelyze``.

Conventions (those of evosoro's ``read_write_voxelyze.py``):

* ``<Structure Compression="ASCII_READABLE">`` holds ``<X_Voxels>``,
  ``<Y_Voxels>``, ``<Z_Voxels>`` and a ``<Data>`` of ``Z_Voxels`` ``<Layer>``
  elements, one per z (bottom first). A layer is a string of ``X*Y``
  characters in x-fastest order (index ``x + X*y``); character ``c`` is
  material id ``ord(c) - ord('0')`` (digits for ids 0-9, as VoxCAD does).
* ``<Palette>`` holds ``<Material ID="k">`` with ``<Name>``,
  ``<Display><Red/><Green/><Blue/><Alpha/>`` and ``<Mechanical>``:
  ``<Elastic_Mod>`` (Pa), ``<Density>`` (kg/m^3), ``<Poissons_Ratio>``,
  ``<CTE>`` (1/°C), ``<uStatic>``, ``<uDynamic>``. Only ``<MatModel>`` 0
  (linear) is supported.
* ``<Environment><Thermal>``: ``<TempAmp>``, ``<TempBase>``, ``<TempPeriod>``.
  The engine drives ``dT = TempAmp - TempBase`` (docs/PHYSICS.md).

Import builds a :class:`~softgym.design.controller.Controller` with
``temp_amplitude = TempAmp - TempBase``, ``period = TempPeriod`` and
``muscle_cte = |CTE of material 3|`` (else ``|CTE of 4|``, else the default).
Export writes ``TempBase = 25`` and ``TempAmp = 25 + dT`` like the seed when
that subtraction gives ``dT`` back exactly, and ``TempBase = 0``,
``TempAmp = dT`` otherwise, so export then import is exact.

Obstacles: voxels inside a ``<FRegion>`` of ``<Boundary_Conditions>`` that fixes all
six degrees of freedom (``<DofFixed>63``) are the seed's walls (its obstacle runs
put 44 of them, material 5, in a 50x50x6 lattice). Import takes them out of the
robot: :attr:`VxaDocument.terrain` holds them as boxes around the robot's grid,
which is cropped to the robot's voxels in x and y; ``to_vxa(terrain=...)``
writes them back the same way.

Every problem with a file raises :class:`~softgym.exceptions.InvalidDesignError`
naming the offending element.
"""

from __future__ import annotations

import logging
import math
import os
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any
from xml.sax.saxutils import escape

import numpy as np

from softgym.design.controller import Controller
from softgym.design.material import MAX_MATERIAL_ID, Material, Palette
from softgym.design.robot import RobotDesign, check_grid_shape
from softgym.exceptions import (
    CheckpointError,
    DesignFileError,
    InvalidDesignError,
    InvalidParameterError,
)
from softgym.io import atomic_write_bytes, read_capped

if TYPE_CHECKING:
    from softgym.terrain import Terrain

__all__ = [
    "MAX_VXA_BYTES",
    "VxaDocument",
    "from_vxa",
    "load_vxa",
    "parse_vxa",
    "save_vxa",
    "to_vxa",
]

#: Largest ``.vxa`` text (bytes) read: a grid of MAX_GRID_VOXELS cells plus a full palette fits.
MAX_VXA_BYTES = 32 * 2**20

logger = logging.getLogger(__name__)

#: Defaults of optional ``<Mechanical>`` tags (the seed's values).
_MECHANICAL_DEFAULTS = {"Poissons_Ratio": 0.35, "CTE": 0.0, "uStatic": 1.0, "uDynamic": 0.5}


@dataclass(frozen=True)
class VxaDocument:
    """A parsed ``.vxa`` file.

    Attributes
    ----------
    design : RobotDesign
        Structure, palette and controller of the robot (the file's fixed
        obstacle voxels taken out, the grid cropped to the robot in x and y).
    voxel_size : float
        ``<Lattice_Dim>`` (m); 0.01 if absent.
    settings : dict of str to str
        Text of every other leaf element of ``<Simulator>`` and
        ``<Environment>`` by tag (e.g. ``"StopConditionValue": "5"``), for
        callers that want the simulation settings.
    terrain : Terrain or None
        The file's fixed obstacle voxels (those inside a ``<FRegion>`` with
        ``<DofFixed>63``) as boxes in voxel lengths around :attr:`design`'s
        grid, one per region, or None when it has none: what
        ``to_vxa(design, terrain=...)`` wrote, and the seed's fence.
    """

    design: RobotDesign
    voxel_size: float = 0.01
    settings: dict[str, str] = field(default_factory=dict)
    terrain: Terrain | None = None


# --------------------------------------------------------------------------------------------
# Import
# --------------------------------------------------------------------------------------------


def _where(elem_path: str) -> str:
    return f"<{elem_path}>"


def _find(parent: ET.Element, tag: str, where: str) -> ET.Element:
    el = parent.find(tag)
    if el is None:
        raise InvalidDesignError(f"VXA file has no <{tag}> element in {where}")
    return el


def _number(el: ET.Element | None, where: str, default: float | None = None) -> float:
    if el is None:
        if default is None:
            raise InvalidDesignError(f"VXA file is missing {where}")
        return default
    text = (el.text or "").strip()
    try:
        value = float(text)
    except ValueError:
        raise InvalidDesignError(f"{where} is not a number: {text!r}") from None
    if not math.isfinite(value):
        raise InvalidDesignError(f"{where} is not finite: {text!r}")
    return value


def _int(el: ET.Element | None, where: str) -> int:
    # a count written as an integer ("6", not "6.5" or "6.0"); range checked by the caller
    if el is None:
        raise InvalidDesignError(f"VXA file is missing {where}")
    text = (el.text or "").strip()
    if not (text.isascii() and text.isdigit()) or len(text) > 9:
        _number(el, where)  # "is not a number" / "is not finite" first
        raise InvalidDesignError(
            f"{where} must be a positive integer of at most 9 digits, got {text!r:.40}"
        )
    return int(text)


def _parse_material(el: ET.Element) -> tuple[int, Material]:
    raw_id = el.get("ID")
    try:
        mid = int(raw_id)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise InvalidDesignError(
            f"<Material> has a missing or non-integer ID attribute: {raw_id!r}"
        ) from None
    where = f'<Material ID="{mid}">'
    if not 1 <= mid <= MAX_MATERIAL_ID:
        raise InvalidDesignError(f"{where}: ids must lie in 1..{MAX_MATERIAL_ID}")
    name_el = el.find("Name")
    name = (name_el.text or "").strip() if name_el is not None else f"Material_{mid}"
    mech = el.find("Mechanical")
    if mech is None:
        raise InvalidDesignError(f"{where} has no <Mechanical> element")
    model = mech.find("MatModel")
    if model is not None and _number(model, f"<MatModel> of {where}") != 0:
        raise InvalidDesignError(
            f"<MatModel> of {where} is {model.text!r}: only linear materials (MatModel 0) are supported"
        )
    values = {
        tag: _number(mech.find(tag), f"<{tag}> of {where}", _MECHANICAL_DEFAULTS.get(tag))
        for tag in ("Elastic_Mod", "Density", "Poissons_Ratio", "CTE", "uStatic", "uDynamic")
    }
    color: tuple[float, ...] = (0.5, 0.5, 0.5, 1.0)
    disp = el.find("Display")
    if disp is not None:
        color = tuple(
            _number(disp.find(c), f"<{c}> of {where}", 1.0 if c == "Alpha" else 0.5)
            for c in ("Red", "Green", "Blue", "Alpha")
        )
    try:
        mat = Material(
            name=name,
            youngs_modulus=values["Elastic_Mod"],
            density=values["Density"],
            poisson=values["Poissons_Ratio"],
            cte=values["CTE"],
            mu_static=values["uStatic"],
            mu_kinetic=values["uDynamic"],
            color=color,
        )
    except InvalidParameterError as exc:
        raise InvalidDesignError(f"{where}: {exc}") from exc
    return mid, mat


def _parse_structure(structure: ET.Element) -> np.ndarray:
    compression = structure.get("Compression", "ASCII_READABLE")
    if compression != "ASCII_READABLE":
        raise InvalidDesignError(
            f'<Structure Compression="{compression}"> is not supported; only ASCII_READABLE is'
        )
    nx = _int(structure.find("X_Voxels"), "<X_Voxels> of <Structure>")
    ny = _int(structure.find("Y_Voxels"), "<Y_Voxels> of <Structure>")
    nz = _int(structure.find("Z_Voxels"), "<Z_Voxels> of <Structure>")
    # against the design caps before the grid (or anything of its size) is allocated
    nx, ny, nz = check_grid_shape((nx, ny, nz), "<X_Voxels>, <Y_Voxels>, <Z_Voxels>")
    data = _find(structure, "Data", "<Structure>")
    layers = data.findall("Layer")
    if len(layers) != nz:
        raise InvalidDesignError(f"<Data> has {len(layers)} <Layer> elements, <Z_Voxels> says {nz}")
    grid = np.zeros((nx, ny, nz), dtype=np.int8)
    for z, layer in enumerate(layers):
        text = (layer.text or "").strip()
        if len(text) != nx * ny:
            raise InvalidDesignError(
                f"<Layer> {z} of <Data> has {len(text)} characters, expected X_Voxels*Y_Voxels = {nx * ny}"
            )
        codes = np.fromiter((ord(c) - 48 for c in text), dtype=np.int64, count=len(text))
        bad = np.flatnonzero((codes < 0) | (codes > MAX_MATERIAL_ID))
        if bad.size:
            raise InvalidDesignError(
                f"<Layer> {z} of <Data> holds an invalid material character {text[bad[0]]!r} at position {bad[0]}"
            )
        grid[:, :, z] = codes.reshape(ny, nx).T
    return grid


def _fixed_regions(root: ET.Element, shape: tuple[int, ...]) -> list[np.ndarray]:
    # voxel masks of the <FRegion>s that fix all six degrees of freedom: a voxel
    # belongs to a region when its centre lies in the region's box (fractions of
    # the lattice, as VoxCAD places them)
    masks = []
    bcs = root.find("Environment/Boundary_Conditions")
    if bcs is None:
        return masks
    centres = [(np.arange(n) + 0.5) / n for n in shape]
    for k, reg in enumerate(bcs.findall("FRegion")):
        where = f"<FRegion> {k} of <Boundary_Conditions>"
        if reg.find("DofFixed") is None or _int(reg.find("DofFixed"), f"<DofFixed> of {where}") != 63:
            continue
        if reg.find("PrimType") is not None and _int(reg.find("PrimType"), f"<PrimType> of {where}") != 0:
            continue  # only boxes (PrimType 0) hold the seed's walls
        lo = [_number(reg.find(t), f"<{t}> of {where}") for t in ("X", "Y", "Z")]
        size = [_number(reg.find(t), f"<{t}> of {where}") for t in ("dX", "dY", "dZ")]
        inside = [(c >= a - 1e-9) & (c <= a + d + 1e-9) for c, a, d in zip(centres, lo, size)]
        masks.append(inside[0][:, None, None] & inside[1][None, :, None] & inside[2][None, None, :])
    return masks


def _split_obstacles(grid: np.ndarray, masks: list[np.ndarray]) -> tuple[np.ndarray, Terrain | None]:
    # the robot's grid (fixed voxels removed, cropped in x and y) and the fixed
    # voxels as terrain boxes around it
    from softgym.terrain import Box, Terrain

    fixed = np.zeros(grid.shape, dtype=bool)
    for m in masks:
        fixed |= m & (grid > 0)
    if not fixed.any():
        return grid, None
    robot = np.where(fixed, 0, grid).astype(np.int8)
    filled = np.argwhere(robot > 0)
    if filled.size == 0:
        raise InvalidDesignError("every voxel of <Data> is a fixed obstacle voxel (<FRegion> with DofFixed 63): no robot")
    lo = filled.min(axis=0)
    hi = filled.max(axis=0) + 1
    off = np.array([lo[0], lo[1], 0])
    robot = robot[lo[0]:hi[0], lo[1]:hi[1], : hi[2]]
    boxes = []
    taken = np.zeros(grid.shape, dtype=bool)
    for m in masks:
        cells = m & fixed & ~taken
        if not cells.any():
            continue
        taken |= cells
        idx = np.argwhere(cells)
        a, b = idx.min(axis=0), idx.max(axis=0) + 1
        if cells[a[0]:b[0], a[1]:b[1], a[2]:b[2]].all():
            boxes.append(Box(tuple(float(v) for v in a - off), tuple(float(v) for v in b - off)))
        else:  # a region that is not a full box: one box per voxel
            boxes += [Box(tuple(float(v) for v in c - off), tuple(float(v) for v in c - off + 1)) for c in idx]
    return robot, Terrain.from_boxes(boxes, name="vxa obstacles")


def parse_vxa(text: str | bytes) -> VxaDocument:
    """Parse the text of a ``.vxa`` file.

    Parameters
    ----------
    text : str or bytes
        The XML; bytes are decoded as the XML declaration says (evosoro
        writes ISO-8859-1).

    Returns
    -------
    VxaDocument

    Raises
    ------
    InvalidDesignError
        If the XML is malformed, an element is missing or holds a bad value,
        a layer has the wrong length, the structure uses an id the palette
        lacks, or the thermal settings are out of the controller's bounds.
    """
    if not isinstance(text, (str, bytes, bytearray)):
        raise InvalidDesignError(f"VXA text must be str or bytes, got {type(text).__name__}")
    if len(text) > MAX_VXA_BYTES:
        raise InvalidDesignError(
            f"VXA text of {len(text)} characters is larger than the cap of {MAX_VXA_BYTES} bytes"
        )
    if isinstance(text, str):
        # A str with an encoding declaration is fine for ElementTree once encoded as UTF-8
        # with the declaration removed.
        stripped = text.lstrip()
        if stripped.startswith("<?xml"):
            end = stripped.find("?>")
            stripped = stripped[end + 2 :] if end >= 0 else stripped
        try:
            source: bytes = stripped.encode("utf-8")
        except UnicodeEncodeError as exc:  # lone surrogates
            raise InvalidDesignError(f"VXA text cannot be encoded: {exc}") from None
    else:
        source = bytes(text)
    try:
        root = ET.fromstring(source)
    except ET.ParseError as exc:
        raise InvalidDesignError(f"malformed VXA XML: {exc}") from None
    except (RecursionError, ValueError, LookupError) as exc:  # e.g. an unknown encoding
        raise InvalidDesignError(f"malformed VXA XML: {exc!s:.200}") from None
    if root.tag != "VXA":
        raise InvalidDesignError(
            f"not a VXA file: the root element is <{root.tag}>, expected <VXA>"
        )
    vxc = _find(root, "VXC", "<VXA>")
    palette_el = _find(vxc, "Palette", "<VXC>")
    materials: dict[int, Material] = {}
    for el in palette_el.findall("Material"):
        mid, mat = _parse_material(el)
        if mid in materials:
            raise InvalidDesignError(f'<Palette> defines <Material ID="{mid}"> twice')
        materials[mid] = mat
    if not materials:
        raise InvalidDesignError("<Palette> defines no <Material>")
    grid = _parse_structure(_find(vxc, "Structure", "<VXC>"))
    grid, terrain = _split_obstacles(grid, _fixed_regions(root, grid.shape))
    used = sorted(int(v) for v in np.unique(grid) if v != 0)
    missing = [v for v in used if v not in materials]
    if missing:
        raise InvalidDesignError(
            f"<Data> uses material ids {missing} that <Palette> does not define"
        )

    lattice = vxc.find("Lattice")
    voxel_size = _number(
        lattice.find("Lattice_Dim") if lattice is not None else None, "<Lattice_Dim>", 0.01
    )
    if voxel_size <= 0:
        raise InvalidDesignError(f"<Lattice_Dim> must be > 0 m, got {voxel_size}")

    env = root.find("Environment")
    thermal = env.find("Thermal") if env is not None else None
    defaults = Controller()
    if thermal is None:
        amplitude, period = defaults.temp_amplitude, defaults.period
    else:
        amp = _number(thermal.find("TempAmp"), "<TempAmp> of <Thermal>")
        base = _number(thermal.find("TempBase"), "<TempBase> of <Thermal>", 0.0)
        amplitude = amp - base
        period = _number(thermal.find("TempPeriod"), "<TempPeriod> of <Thermal>", defaults.period)
    plus, minus = Controller.MUSCLE_PAIR
    if plus in materials:
        muscle_cte = abs(materials[plus].cte)
    elif minus in materials:
        muscle_cte = abs(materials[minus].cte)
    else:
        muscle_cte = defaults.muscle_cte
    if plus in materials and minus in materials and materials[minus].cte != -materials[plus].cte:
        logger.warning(
            "VXA materials %d and %d have CTE %g and %g; softgym drives them with +/-%g",
            plus,
            minus,
            materials[plus].cte,
            materials[minus].cte,
            muscle_cte,
        )
    try:
        controller = Controller(temp_amplitude=amplitude, period=period, muscle_cte=muscle_cte)
    except InvalidParameterError as exc:
        raise InvalidDesignError(
            f"<Thermal> settings / muscle CTE of the VXA file give an invalid controller: {exc}"
        ) from exc
    design = RobotDesign(grid=grid, palette=Palette(materials), controller=controller)

    settings: dict[str, str] = {}
    for section in (root.find("Simulator"), env):
        if section is None:
            continue
        for el in section.iter():
            if len(el) == 0 and el is not section and el.text is not None and el.text.strip():
                settings[el.tag] = el.text.strip()
    return VxaDocument(design=design, voxel_size=voxel_size, settings=settings, terrain=terrain)


def from_vxa(text: str | bytes) -> RobotDesign:
    """The :class:`RobotDesign` of a ``.vxa`` file's text (its robot: fixed obstacle
    voxels are :attr:`VxaDocument.terrain` of :func:`parse_vxa`).
    """
    return parse_vxa(text).design


def load_vxa(path: str | os.PathLike[str]) -> RobotDesign:
    """Read the :class:`RobotDesign` of a ``.vxa`` file; see :func:`parse_vxa`.

    Raises
    ------
    DesignFileError
        Naming the file, if it is missing, a folder, unreadable or larger than
        :data:`MAX_VXA_BYTES` (also an ``OSError``).
    InvalidDesignError
        Naming the file, if its content is not a valid ``.vxa`` design.
    """
    path = os.fspath(path)
    data = read_capped(path, MAX_VXA_BYTES, "VXA", DesignFileError)
    try:
        return parse_vxa(data).design
    except InvalidDesignError as exc:
        raise InvalidDesignError(f"VXA file {path!r}: {exc}") from exc


# --------------------------------------------------------------------------------------------
# Export
# --------------------------------------------------------------------------------------------


def _num(v: float) -> str:
    """Exact text of a float (repr), integers without a trailing '.0'."""
    v = float(v)
    return str(int(v)) if v.is_integer() and abs(v) < 1e15 else repr(v)


def _thermal(amplitude: float) -> tuple[float, float]:
    base = 25.0
    amp = base + amplitude
    if amp - base == amplitude:
        return amp, base
    return amplitude, 0.0


#: Palette id of the seed's wall material (its material 5, "Obstacle").
OBSTACLE_ID = 5


def _with_obstacles(design: RobotDesign, terrain: Any) -> tuple[RobotDesign, list[tuple[float, ...]]]:
    # the design inside a lattice that also holds the terrain's boxes as fixed
    # Obstacle voxels; regions: (X, Y, Z, dX, dY, dZ) of each box as fractions
    # of the lattice (the seed's <FRegion> geometry)
    from softgym.exceptions import InvalidTerrainError

    if OBSTACLE_ID not in design.palette or design.palette[OBSTACLE_ID].name != "Obstacle":
        raise InvalidTerrainError(f"to_vxa(terrain=...) needs the Obstacle material at palette id {OBSTACLE_ID}")
    boxes = []
    for b in terrain.boxes:
        lo = np.asarray(b.lo, dtype=np.float64)
        hi = np.asarray(b.hi, dtype=np.float64)
        if np.any(np.abs(lo - np.rint(lo)) > 1e-9) or np.any(np.abs(hi - np.rint(hi)) > 1e-9):
            raise InvalidTerrainError(f"to_vxa: box {b.lo}-{b.hi} is off the lattice (corners must be integers)")
        if lo[2] < 0:
            raise InvalidTerrainError(f"to_vxa: box {b.lo}-{b.hi} reaches below the floor")
        boxes.append((np.rint(lo).astype(int), np.rint(hi).astype(int)))
    lo_all = np.minimum(np.min([lo for lo, _ in boxes], axis=0), 0)
    lo_all[2] = 0
    hi_all = np.maximum(np.max([hi for _, hi in boxes], axis=0), np.array(design.shape))
    off = -lo_all
    shape = tuple(int(v) for v in hi_all - lo_all)
    check_grid_shape(shape, "to_vxa lattice with obstacles")
    grid = np.zeros(shape, dtype=np.int8)
    for lo, hi in boxes:
        a, b = lo + off, hi + off
        grid[a[0]:b[0], a[1]:b[1], a[2]:b[2]] = OBSTACLE_ID
    nx, ny, nz = design.shape
    robot = grid[off[0]:off[0] + nx, off[1]:off[1] + ny, :nz]
    if np.any((robot == OBSTACLE_ID) & (design.grid > 0)):
        raise InvalidTerrainError("to_vxa: a terrain box overlaps the robot")
    robot[design.grid > 0] = design.grid[design.grid > 0]
    ex, ey, ez = shape
    regions = [((lo[0] + off[0]) / ex, (lo[1] + off[1]) / ey, (lo[2] + off[2]) / ez,
                (hi[0] - lo[0]) / ex, (hi[1] - lo[1]) / ey, (hi[2] - lo[2]) / ez)
               for lo, hi in boxes]  # fmt: skip
    return design.replace(grid=grid), regions


def _boundary_conditions(regions: list[tuple[float, ...]]) -> str:
    if not regions:
        return "  <Fixed_Regions><NumFixed>0</NumFixed></Fixed_Regions>"
    parts = [f"  <Boundary_Conditions><NumBCs>{len(regions)}</NumBCs>"]
    for x, y, z, dx, dy, dz in regions:
        parts.append(
            f"<FRegion><PrimType>0</PrimType><X>{x:.12g}</X><Y>{y:.12g}</Y><Z>{z:.12g}</Z>"
            f"<dX>{dx:.12g}</dX><dY>{dy:.12g}</dY><dZ>{dz:.12g}</dZ>"
            "<alfa>1</alfa><DofFixed>63</DofFixed></FRegion>"
        )
    parts.append("</Boundary_Conditions>")
    return "".join(parts)


def to_vxa(
    design: RobotDesign,
    *,
    voxel_size: float = 0.01,
    sim_time: float = 5.0,
    init_time: float = 1.0,
    dt_frac: float = 0.9,
    time_between_traces: float = 0.0,
    self_collisions: bool = True,
    terrain: Any = None,
) -> str:
    """The ``.vxa`` text of a design, with the seed's simulation settings.

    Parameters
    ----------
    design : RobotDesign
    voxel_size : float
        ``<Lattice_Dim>`` (m).
    sim_time, init_time : float
        ``<StopConditionValue>`` and ``<InitCmTime>`` (s).
    dt_frac : float
        ``<DtFrac>``.
    time_between_traces : float
        ``<TimeBetweenTraces>`` (s); > 0 also sets ``<SaveTraces>`` 1.
    self_collisions : bool
        ``<SelfColEnabled>``.
    terrain : Terrain, optional
        Obstacles, written as the seed wrote its walls: voxels of the Obstacle
        material (id 5) in the lattice, fixed by one ``<FRegion>`` per box
        (``DofFixed`` 63), the lattice widened to hold them (the robot keeps
        its place relative to them). Boxes must lie on the lattice (integer
        corners in voxel lengths, nothing below the floor).

    Returns
    -------
    str
        ISO-8859-1-declared XML; non-ASCII characters of material names are
        written as character references.

    Raises
    ------
    InvalidTerrainError
        A box off the lattice, below the floor, or over the robot; or no
        Obstacle material at id 5 in the design's palette.
    """
    regions: list[tuple[float, ...]] = []
    if terrain is not None and terrain.boxes:
        design, regions = _with_obstacles(design, terrain)
    amp, base = _thermal(design.controller.temp_amplitude)
    lines = [
        '<?xml version="1.0" encoding="ISO-8859-1"?>',
        '<VXA Version="1.0">',
        "<Simulator>",
        "  <Integration><Integrator>0</Integrator><DtFrac>"
        + _num(dt_frac)
        + "</DtFrac></Integration>",
        "  <Damping><BondDampingZ>1</BondDampingZ><ColDampingZ>0.8</ColDampingZ>"
        "<SlowDampingZ>0.01</SlowDampingZ></Damping>",
        f"  <Collisions><SelfColEnabled>{int(self_collisions)}</SelfColEnabled><ColSystem>3</ColSystem>"
        "<CollisionHorizon>2</CollisionHorizon></Collisions>",
        "  <Features><FluidDampEnabled>0</FluidDampEnabled><PoissonKickBackEnabled>0</PoissonKickBackEnabled>"
        "<EnforceLatticeEnabled>0</EnforceLatticeEnabled></Features>",
        "  <StopCondition><StopConditionType>2</StopConditionType>"
        f"<StopConditionValue>{_num(sim_time)}</StopConditionValue><AfterlifeTime>0</AfterlifeTime>"
        f"<MidLifeFreezeTime>0</MidLifeFreezeTime><InitCmTime>{_num(init_time)}</InitCmTime></StopCondition>",
        "  <EquilibriumMode><EquilibriumModeEnabled>0</EquilibriumModeEnabled></EquilibriumMode>",
        "  <GA><WriteFitnessFile>1</WriteFitnessFile><FitnessFileName>softbotsOutput.xml</FitnessFileName></GA>",
        "  <MinTempFact>0.1</MinTempFact>",
        "  <MaxTempFactChange>1e-05</MaxTempFactChange>",
        "  <MaxStiffnessChange>10000</MaxStiffnessChange>",
        "  <MinElasticMod>5000000</MinElasticMod>",
        "  <MaxElasticMod>500000000</MaxElasticMod>",
        "</Simulator>",
        "<Environment>",
        _boundary_conditions(regions),
        "  <Forced_Regions><NumForced>0</NumForced></Forced_Regions>",
        "  <Gravity><GravEnabled>1</GravEnabled><GravAcc>-9.81</GravAcc><FloorEnabled>1</FloorEnabled>"
        "<FloorSlope>0</FloorSlope></Gravity>",
        "  <Thermal>",
        "    <TempEnabled>1</TempEnabled>",
        f"    <TempAmp>{_num(amp)}</TempAmp>",
        f"    <TempBase>{_num(base)}</TempBase>",
        "    <VaryTempEnabled>1</VaryTempEnabled>",
        f"    <TempPeriod>{_num(design.controller.period)}</TempPeriod>",
        "  </Thermal>",
        f"  <TimeBetweenTraces>{_num(time_between_traces)}</TimeBetweenTraces>",
        f"  <SaveTraces>{int(time_between_traces > 0)}</SaveTraces>",
        "  <StickyFloor>0</StickyFloor>",
        "</Environment>",
        '<VXC Version="0.93">',
        "  <Lattice>",
        f"    <Lattice_Dim>{_num(voxel_size)}</Lattice_Dim>",
        "    <X_Dim_Adj>1</X_Dim_Adj><Y_Dim_Adj>1</Y_Dim_Adj><Z_Dim_Adj>1</Z_Dim_Adj>",
        "    <X_Line_Offset>0</X_Line_Offset><Y_Line_Offset>0</Y_Line_Offset>",
        "    <X_Layer_Offset>0</X_Layer_Offset><Y_Layer_Offset>0</Y_Layer_Offset>",
        "  </Lattice>",
        "  <Voxel><Vox_Name>BOX</Vox_Name><X_Squeeze>1</X_Squeeze><Y_Squeeze>1</Y_Squeeze>"
        "<Z_Squeeze>1</Z_Squeeze></Voxel>",
        "  <Palette>",
    ]
    for mid, mat in design.palette.items():
        r, g, b, a = mat.color
        name = escape(mat.name).encode("ascii", "xmlcharrefreplace").decode("ascii")
        lines += [
            f'    <Material ID="{mid}">',
            "      <MatType>0</MatType>",
            f"      <Name>{name}</Name>",
            f"      <Display><Red>{_num(r)}</Red><Green>{_num(g)}</Green><Blue>{_num(b)}</Blue>"
            f"<Alpha>{_num(a)}</Alpha></Display>",
            "      <Mechanical>",
            "        <MatModel>0</MatModel>",
            f"        <Elastic_Mod>{_num(mat.youngs_modulus)}</Elastic_Mod>",
            "        <Plastic_Mod>0</Plastic_Mod><Yield_Stress>0</Yield_Stress><FailModel>0</FailModel>"
            "<Fail_Stress>0</Fail_Stress><Fail_Strain>0</Fail_Strain>",
            f"        <Density>{_num(mat.density)}</Density>",
            f"        <Poissons_Ratio>{_num(mat.poisson)}</Poissons_Ratio>",
            f"        <CTE>{_num(mat.cte)}</CTE>",
            f"        <uStatic>{_num(mat.mu_static)}</uStatic>",
            f"        <uDynamic>{_num(mat.mu_kinetic)}</uDynamic>",
            "      </Mechanical>",
            "    </Material>",
        ]
    nx, ny, nz = design.shape
    lines += [
        "  </Palette>",
        '  <Structure Compression="ASCII_READABLE">',
        f"    <X_Voxels>{nx}</X_Voxels>",
        f"    <Y_Voxels>{ny}</Y_Voxels>",
        f"    <Z_Voxels>{nz}</Z_Voxels>",
        "    <Data>",
    ]
    for z in range(nz):
        layer = "".join(chr(48 + v) for v in design.grid[:, :, z].T.ravel().tolist())
        if layer.isdigit():
            lines.append(f"      <Layer><![CDATA[{layer}]]></Layer>")
        else:  # ids >= 10 use characters after '9' (VoxCAD's convention); escape them
            lines.append(f"      <Layer>{escape(layer)}</Layer>")
    lines += ["    </Data>", "  </Structure>", "</VXC>", "</VXA>", ""]
    return "\n".join(lines)


def save_vxa(design: RobotDesign, path: str | os.PathLike[str], **kwargs: float | bool) -> None:
    """Write :func:`to_vxa` of ``design`` to ``path`` (ISO-8859-1), atomically.

    Keyword arguments go to :func:`to_vxa`. A folder or an unwritable place at
    ``path`` raises :class:`DesignFileError` naming it; no temporary file is
    left behind.
    """
    data = to_vxa(design, **kwargs).encode("latin-1")  # type: ignore[arg-type]
    try:
        atomic_write_bytes(path, data)
    except CheckpointError as exc:
        raise DesignFileError(f"VXA file {os.fspath(path)!r}: {exc}") from None

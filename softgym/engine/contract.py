"""The kernel's data contract, in one table: what crosses from Python into the compiled engine.

Every array the kernel reads or writes (:data:`ARRAYS`: name, dtype, C type, which
part of the batch it belongs to, shape, whether it may be empty, what it holds and in
which units), every scalar setting (:data:`SETTINGS`) and the named codes of the
settings and results that are codes (:data:`MODEL`, :data:`ACTUATION`, :data:`STATUS`).

The rest is derived from this table, never kept by hand beside it:

- ``_batch.pxd``: the ``Batch`` struct's array and setting fields (each with its shape
  and units) and the codes' ``cdef enum`` s (``MODEL_SEED``...), rendered from
  ``_batch.pxd.tp``;
- ``_bind.pyx``: ``bind``, which points a ``Batch`` at a batch's arrays and settings,
  rendered from ``_bind.pyx.tp``;
- :data:`KERNEL_ARRAYS`, and the dtype and shape checks of
  :func:`softgym.engine.layout.build_layout` (:func:`check_arrays`).

``setup.py`` renders the two files before it compiles (``softgym/engine/_codegen.py``);
``python softgym/engine/_codegen.py`` renders them without a build (they are committed,
and ``tests/engine/test_contract.py`` fails when they are out of date with this table).
A new kernel array or material property is one entry here plus the kernel code that
reads it (``CONTRIBUTING.md``).

This module imports nothing but the standard library (``setup.py`` loads it from its file
before the package is built).
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

__all__ = [
    "ACTUATION",
    "ARRAYS",
    "COUNTS",
    "CTYPES",
    "KERNEL_ARRAYS",
    "MODEL",
    "SECTIONS",
    "SETTINGS",
    "STATUS",
    "Code",
    "CodeTable",
    "KernelArray",
    "Setting",
    "array",
    "check_arrays",
    "check_settings",
    "counts_of",
    "expected_dtype",
    "expected_shape",
]

#: The parts of a batch an array belongs to, in the order of ``Batch``'s fields.
SECTIONS: tuple[str, ...] = ("robot", "voxel", "link")

#: The C type (``_typedefs.pxd``) of each array element and the NumPy dtype it is stored in.
CTYPES: dict[str, str] = {
    "float64_t": "float64",
    "float": "float32",
    "intp_t": "intp",
    "step_t": "int64",
    "lane_flag_t": "int64",
    "int32": "int32",
    "flag_t": "int8",
}

#: The counts that shapes name, and where a batch holds each (:func:`counts_of`). Shapes
#: also name the kernel's constants ``N_AUX`` (columns of ``robot_aux``) and
#: ``FM_STRIDE`` (doubles in a voxel's row of ``force``), which the caller passes.
COUNTS: dict[str, str] = {
    "n_robots": "settings['n_robots']",
    "n_voxels": "vox_start[n_robots]",
    "n_links": "link_start[n_robots]",
    "n_boxes": "box_start[n_robots]",
    "n_obs": "obs_start[n_robots]",
    "n_excl": "excl_start[n_voxels]",
    "trace_capacity": "trace_t.shape[1]",
}


@dataclass(frozen=True)
class Code:
    """One named value of a :class:`CodeTable`.

    Attributes
    ----------
    name : str
        Its name in Python (``"seed"``); in C it is ``PREFIX_NAME`` (``MODEL_SEED``).
    value : int
        The number the kernel sees.
    doc : str
        What it means (the enum's comment in ``_batch.pxd``).
    """

    name: str
    value: int
    doc: str


@dataclass(frozen=True)
class CodeTable:
    """Named codes of one setting or result, a ``cdef enum`` in ``_batch.pxd``.

    Attributes
    ----------
    prefix : str
        The C names' prefix (``MODEL``: ``MODEL_SEED``, ``MODEL_COROTATIONAL``).
    doc : str
        What the codes are codes of (the enum's comment).
    codes : tuple of Code
        The codes, values distinct.
    """

    prefix: str
    doc: str
    codes: tuple[Code, ...]

    def __getitem__(self, name: str) -> int:
        for c in self.codes:
            if c.name == name:
                return c.value
        raise KeyError(f"{self.prefix.lower()} code {name!r} unknown: one of {self.names}")

    def __contains__(self, name: object) -> bool:
        return any(c.name == name for c in self.codes)

    @property
    def names(self) -> tuple[str, ...]:
        """The codes' names, in value order."""
        return tuple(c.name for c in self.codes)

    def as_dict(self) -> dict[str, int]:
        """``{name: value}`` of every code."""
        return {c.name: c.value for c in self.codes}

    def cname(self, name: str) -> str:
        """The C name of code ``name`` (``MODEL.cname("seed") == "MODEL_SEED"``)."""
        self[name]
        return f"{self.prefix}_{name.upper()}"


@dataclass(frozen=True)
class Setting:
    """A scalar setting of the batch (a field of ``Batch``, an entry of ``settings``).

    Attributes
    ----------
    name : str
        The field's and the ``settings`` key's name.
    ctype : str
        Its C type (``_typedefs.pxd``).
    doc : str
        What it is, with units.
    """

    name: str
    ctype: str
    doc: str


@dataclass(frozen=True)
class KernelArray:
    """An array of the batch that the kernel reads or writes (a pointer field of ``Batch``).

    Attributes
    ----------
    name : str
        Its key in the arrays dict and its field in ``Batch``.
    section : str
        Which part of the batch indexes its rows: ``"robot"``, ``"voxel"`` or ``"link"``
        (:data:`SECTIONS`; an array of ``n_boxes``/``n_obs``/``n_excl`` rows belongs to the
        robot or voxel whose CSR row points into it).
    ctype : str
        The C type of an element (a key of :data:`CTYPES`, which gives its dtype).
    shape : tuple of int or str
        Its shape: numbers, and counts by name (``"n_voxels"``, ``"n_robots + 1"``,
        ``"N_AUX"``; :func:`expected_shape`).
    doc : str
        What it holds, with units (its comment in ``_batch.pxd``, after the shape).
    nullable : bool
        The kernel gets NULL when it is empty (never dereferenced then: no boxes, no
        links...); otherwise its data pointer, empty or not.
    padded : bool
        A (rows, n_links) array whose rows are ``row_stride(n_links)`` elements apart
        (``layout._link_rows``; the forces pass reads all such arrays with one stride,
        ``Batch.link_rows``, which ``bind`` checks).
    single : str or None
        With single-precision links (the setting ``link_f32``) the array is float32 and
        bound to this field (also a ``float*`` of ``Batch``) instead, its own field NULL.
    single_only : bool
        Used by single-precision links only: without ``link_f32`` its link columns are
        empty (and it is NULL).
    """

    name: str
    section: str
    ctype: str
    shape: tuple[int | str, ...]
    doc: str
    nullable: bool = False
    padded: bool = False
    single: str | None = None
    single_only: bool = False

    @property
    def dtype(self) -> str:
        """The dtype of its elements (without single-precision links)."""
        return CTYPES[self.ctype]


def _a(name, section, ctype, shape, doc, **kw):
    return KernelArray(name, section, ctype, tuple(shape), doc, **kw)


# Per-link arrays are empty (and NULL) in a batch without links.
_LINK = {"nullable": True}

#: Every scalar setting of the batch, in the order of ``Batch``'s fields.
SETTINGS: tuple[Setting, ...] = (
    Setting("n_robots", "intp_t", "robots in the batch"),
    Setting("L", "float64_t", "lattice dimension, nominal voxel edge (m)"),
    Setting("gravity", "float64_t", "gravitational acceleration along +z (m/s^2; -9.81 = down)"),
    Setting("init_time", "float64_t",
            "settling time: no sinusoidal actuation before it; IniCM after it (s)"),
    Setting("min_scale", "float64_t", "smallest actuated edge, as a fraction of L"),
    Setting("max_strain", "float64_t", "divergence threshold on |link engineering strain|"),
    Setting("trace_interval", "float64_t", "seconds between centre-of-mass samples"),
    Setting("self_collision", "int32",
            "1: contact between voxels more than the exclusion hops apart"),
    Setting("actuation_mode", "int32", "an ACTUATION_* code: how the drive limits sizes"),
    Setting("model", "int32", "a MODEL_* code: which step the kernel runs"),
    Setting("bond_zeta", "float64_t",
            "the seed's BondDampingZ (MODEL_SEED's finite-difference link damping)"),
    Setting("link_f32", "int32",
            "MODEL_SEED's frames and forces passes in single precision (1) or double (0)"),
    Setting("fluid_drag", "float64_t",
            "1/2 rho C_d of a surrounding fluid (kg/m^3): quadratic drag on each exposed face "
            "moving into it; 0: no fluid"),
)  # fmt: skip

#: Every array that crosses into the kernel, by section, in the order of ``Batch``'s fields.
ARRAYS: tuple[KernelArray, ...] = (
    # ---- per robot
    _a("vox_start", "robot", "intp_t", ["n_robots + 1"],
       "robot r owns voxels [vox_start[r], vox_start[r+1])"),
    _a("link_start", "robot", "intp_t", ["n_robots + 1"],
       "robot r owns links [link_start[r], link_start[r+1])"),
    _a("link_axis_count", "robot", "intp_t", ["n_robots", 3],
       "its links along x, then y, then z (sorted by axis)"),
    _a("dt", "robot", "float64_t", ["n_robots"], "time step (s)"),
    _a("steps", "robot", "step_t", ["n_robots"], "steps taken; the robot's clock is steps * dt"),
    _a("temp_amp", "robot", "float64_t", ["n_robots"],
       "amplitude dT of the temperature sinusoid (degC)"),
    _a("period", "robot", "float64_t", ["n_robots"], "period of the temperature sinusoid (s)"),
    _a("use_temp", "robot", "flag_t", ["n_robots"],
       "1: per-voxel temperatures replace the sinusoid"),
    _a("floor", "robot", "flag_t", ["n_robots"],
       "1: floor plane z = 0 with penalty contact and friction"),
    _a("box_start", "robot", "intp_t", ["n_robots + 1"],
       "robot r's obstacles are boxes [box_start[r], box_start[r+1])"),
    _a("boxes", "robot", "float64_t", ["n_boxes", 6], "static boxes x0, y0, z0, x1, y1, z1 (m)",
       nullable=True),
    _a("diverged", "robot", "flag_t", ["n_robots"], "1: frozen after divergence"),
    _a("diverged_time", "robot", "float64_t", ["n_robots"], "time of divergence (s)"),
    _a("diverged_code", "robot", "int32", ["n_robots"], "STATUS_* code of the divergence"),
    _a("init_done", "robot", "flag_t", ["n_robots"], "1: cm_init recorded"),
    _a("cm_init", "robot", "float64_t", ["n_robots", 3],
       "CM at the first step with t > init_time (m)"),
    _a("mass_total", "robot", "float64_t", ["n_robots"], "total mass (kg)"),
    _a("trace_n", "robot", "intp_t", ["n_robots"], "samples recorded"),
    _a("trace_t", "robot", "float64_t", ["n_robots", "trace_capacity"], "sample times (s)"),
    _a("trace_cm", "robot", "float64_t", ["n_robots", "trace_capacity", 3], "sampled CM (m)"),
    _a("body_end", "robot", "intp_t", ["n_robots"],
       "robot r's own voxels are [vox_start[r], body_end[r]); the rest of its range are "
       "passive objects (CTE 0, outside its CM)"),
    _a("aux_init", "robot", "float64_t", ["n_robots", "N_AUX"],
       "robot_aux when cm_init was recorded"),
    _a("trace_aux", "robot", "float64_t", ["n_robots", "trace_capacity", "N_AUX"],
       "robot_aux at each CM sample"),
    _a("col_acc", "robot", "float64_t", ["n_robots"],
       "MODEL_SEED: the seed's displacement since the last candidate rebuild, in L (state)"),
    _a("col_vmax", "robot", "float64_t", ["n_robots"],
       "MODEL_SEED: fastest voxel speed after the last step (state)"),
    _a("obs_start", "robot", "intp_t", ["n_robots + 1"],
       "MODEL_SEED: robot r's obstacle voxels [obs_start[r], obs_start[r+1])"),
    _a("obs", "robot", "float64_t", ["n_obs", 4],
       "MODEL_SEED: fixed obstacle voxel centre (m) and its 2 E L (N/m)", nullable=True),
    _a("obs_rank", "robot", "intp_t", ["n_obs"],
       "MODEL_SEED: its index in the seed engine's voxel order", nullable=True),
    # ---- per voxel
    _a("pos", "voxel", "float64_t", ["n_voxels", 3], "centre position (m)"),
    _a("vel", "voxel", "float64_t", ["n_voxels", 3], "velocity (m/s)"),
    _a("quat", "voxel", "float64_t", ["n_voxels", 4], "orientation, unit quaternion (w, x, y, z)"),
    _a("angvel", "voxel", "float64_t", ["n_voxels", 3], "angular velocity, world frame (rad/s)"),
    _a("rot", "voxel", "float64_t", ["n_voxels", 9],
       "rotation matrix of quat, row-major (derived)"),
    _a("force", "voxel", "float64_t", ["n_voxels", "FM_STRIDE"],
       "scratch, one 64-byte row a voxel: accumulated force (N) in columns 0-2, moment (N m) "
       "in 4-6; columns 3 and 7 pad it (the vector scatters add whole rows) and are never "
       "read; voxel i's force at force[SOFTGYM_FM_STRIDE * i] (moment: Batch.moment)"),
    _a("ext_force", "voxel", "float64_t", ["n_voxels", 3], "constant external force (N)"),
    _a("mass", "voxel", "float64_t", ["n_voxels"], "rho L^3 (kg)"),
    _a("inv_mass", "voxel", "float64_t", ["n_voxels"], "1 / mass"),
    _a("inv_inertia", "voxel", "float64_t", ["n_voxels"], "1 / (mass L^2 / 6)"),
    _a("scale", "voxel", "float64_t", ["n_voxels"], "current actuated edge length (m)"),
    _a("cte", "voxel", "float64_t", ["n_voxels"], "coefficient of thermal expansion (1/degC)"),
    _a("cos_phase", "voxel", "float64_t", ["n_voxels"], "cos of the voxel's phase offset"),
    _a("sin_phase", "voxel", "float64_t", ["n_voxels"], "sin of the voxel's phase offset"),
    _a("temp", "voxel", "float64_t", ["n_voxels"], "temperature used when use_temp (degC)"),
    _a("k_floor", "voxel", "float64_t", ["n_voxels"], "floor penalty stiffness 2 E L (N/m)"),
    _a("c_floor", "voxel", "float64_t", ["n_voxels"],
       "floor normal damping zeta_c 2 sqrt(m E L) (N s/m)"),
    _a("c_global", "voxel", "float64_t", ["n_voxels"],
       "global damping zeta_g 2 sqrt(m E L) (N s/m)"),
    _a("rot_damp", "voxel", "float64_t", ["n_voxels"],
       "per-step angular momentum factor of global damping"),
    _a("mu_s", "voxel", "float64_t", ["n_voxels"], "static friction coefficient"),
    _a("mu_k", "voxel", "float64_t", ["n_voxels"], "kinetic friction coefficient"),
    _a("fixed", "voxel", "flag_t", ["n_voxels"], "1: all six degrees of freedom fixed"),
    _a("surface", "voxel", "flag_t", ["n_voxels"],
       "1: misses a face bond (takes part in self-collision)"),
    _a("excl_start", "voxel", "intp_t", ["n_voxels + 1"],
       "CSR rows of voxels that never collide with voxel i"),
    _a("excl_idx", "voxel", "intp_t", ["n_excl"], "their indices, sorted within each row",
       nullable=True),
    _a("faces", "voxel", "flag_t", ["n_voxels"],
       "exposed faces in the voxel's frame: bit 2a the -a face, bit 2a + 1 the +a face "
       "(a = 0, 1, 2 for x, y, z); for fluid drag"),
    _a("seed_rank", "voxel", "intp_t", ["n_voxels"],
       "MODEL_SEED: the voxel's index in the seed engine's order"),
    _a("col_ref", "voxel", "float64_t", ["n_voxels", 4],
       "MODEL_SEED: position and size at the last candidate rebuild (state)"),
    # ---- per link (beam between face neighbours v1 -> v2 along +axis)
    _a("v1", "link", "intp_t", ["n_links"], "voxel on the negative side", **_LINK),
    _a("v2", "link", "intp_t", ["n_links"], "voxel on the positive side", **_LINK),
    _a("axis", "link", "int32", ["n_links"], "0, 1, 2 for x, y, z", **_LINK),
    _a("k_axial", "link", "float64_t", ["n_links"], "E L (N/m)", **_LINK),
    _a("k_torsion", "link", "float64_t", ["n_links"], "E L^3 / (12 (1 + nu)) (N m/rad)", **_LINK),
    _a("k_bend", "link", "float64_t", ["n_links"], "E L^3 / 6 (N m/rad), the b3 of the seed",
       **_LINK),
    _a("c_axial", "link", "float64_t", ["n_links"], "axial damping (N s/m)", **_LINK),
    _a("c_torsion", "link", "float64_t", ["n_links"], "torsional damping (N m s/rad)", **_LINK),
    _a("c_bend", "link", "float64_t", ["n_links"], "bending damping (N m s/rad)", **_LINK),
    _a("c_seed", "link", "float64_t", [8, "n_links"],
       "MODEL_SEED: 2 sqrt(k m) damping constants of voxel 1 then voxel 2: a1 M, b2 FM, "
       "a2 I, b3 I (FM = M L / 2, I = M L^2 / 6)", padded=True, **_LINK),
    _a("homog", "link", "lane_flag_t", ["n_links"],
       "MODEL_SEED: 1: voxel 2 gets -F1 (one material, or two with equal damping constants "
       "a M, b2 FM: layout._robot_entry)", **_LINK),
    _a("k_seed32", "link", "float", [11, "n_links"],
       "MODEL_SEED with link_f32: k_axial, k_torsion, k_bend, c_seed's 8 rows in float32",
       padded=True, single_only=True, **_LINK),
    _a("link_sa", "link", "lane_flag_t", ["n_links"],
       "MODEL_SEED: 1: small-angle mode (state; int8 in states: simulation._STATE_DTYPE)",
       **_LINK),
    _a("link_last", "link", "float64_t", [9, "n_links"],
       "MODEL_SEED: last Pos2, Angle1, Angle2 in the bond frame (state; "
       "Simulation.get_state/set_state show it as (n_links, 9))",
       padded=True, single="link_last32", **_LINK),
)  # fmt: skip

#: The names of :data:`ARRAYS`: the arrays the Python side must provide.
KERNEL_ARRAYS: tuple[str, ...] = tuple(a.name for a in ARRAYS)

_BY_NAME: dict[str, KernelArray] = {a.name: a for a in ARRAYS}

#: ``Batch.model``: which step the kernel runs (``SimConfig.model``).
MODEL = CodeTable("MODEL", "Batch.model, the step the kernel runs (SimConfig.model)", (
    Code("seed", 0, "the seed engine's step (_seed.pyx, _core._advance_seed)"),
    Code("corotational", 1, "co-rotational beams (_corotational.pyx, _core._advance_corotational)"),
))  # fmt: skip

#: ``Batch.actuation_mode``: how the drive limits a voxel's size (``SimConfig.actuation``).
ACTUATION = CodeTable("ACTUATION", "Batch.actuation_mode, how the drive limits a voxel's "
                      "size (SimConfig.actuation)", (
    Code("seed", 0, "contraction only: a size outside [min_scale L, L] keeps the last one"),
    Code("symmetric", 1, "expansion and contraction, clipped below at min_scale L"),
))  # fmt: skip

#: What the kernel's nogil functions return (errors cross nogil as codes) and
#: ``diverged_code`` holds.
STATUS = CodeTable("STATUS", "what the nogil helpers return (errors cross nogil as codes) and "
                   "diverged_code holds", (
    Code("ok", 0, "no error"),
    Code("strain", 1, "a link's engineering strain exceeded max_strain (or was NaN)"),
    Code("nonfinite", 2, "a voxel's position became non-finite or ran away"),
    Code("memory", 3, "the self-collision candidate list could not be allocated"),
))  # fmt: skip


def array(name: str) -> KernelArray:
    """The entry of kernel array ``name``.

    Raises
    ------
    KeyError
        If no kernel array has that name.
    """
    try:
        return _BY_NAME[name]
    except KeyError:
        raise KeyError(f"{name!r} is not a kernel array (softgym.engine.contract.ARRAYS)") from None


def expected_dtype(spec: KernelArray, link_f32: bool) -> str:
    """The dtype of array ``spec`` in a batch with (``link_f32``) or without single-precision links."""
    return "float32" if spec.single is not None and link_f32 else spec.dtype


_DIM = re.compile(r"^([A-Za-z_]\w*)(?:\s*\+\s*(\d+))?$")


def expected_shape(spec: KernelArray, counts: Mapping[str, int]) -> tuple[int, ...]:
    """The shape of array ``spec`` for the batch whose counts are ``counts``.

    Parameters
    ----------
    spec : KernelArray
        The array.
    counts : mapping of str to int
        Every count its shape names (:func:`counts_of`, with the kernel's constants
        ``N_AUX`` and ``FM_STRIDE``) and ``link_f32`` (an array used by single-precision
        links only has no link columns without them).

    Returns
    -------
    tuple of int
    """
    out = []
    for dim in spec.shape:
        if isinstance(dim, int):
            out.append(dim)
            continue
        m = _DIM.match(dim)
        if m is None or m.group(1) not in counts:
            raise KeyError(f"{spec.name}: shape {dim!r} names no count of {sorted(counts)}")
        if m.group(1) == "n_links" and spec.single_only and not counts.get("link_f32"):
            out.append(0)
            continue
        out.append(int(counts[m.group(1)]) + int(m.group(2) or 0))
    return tuple(out)


def counts_of(arrays: Mapping[str, Any], settings: Mapping[str, Any]) -> dict[str, int]:
    """The counts that shapes name, read from a batch's CSR offsets and settings.

    Parameters
    ----------
    arrays : mapping of str to ndarray
        The batch's arrays (their ``*_start`` offsets and ``trace_t`` are read).
    settings : mapping
        The batch's settings (``n_robots``, ``link_f32``).

    Returns
    -------
    dict of str to int
        Every count of :data:`COUNTS`, and ``link_f32``.
    """
    n = int(settings["n_robots"])

    def last(name: str) -> int:
        x = arrays[name]
        return int(x[-1]) if len(x) else 0

    return {
        "n_robots": n,
        "n_voxels": last("vox_start"),
        "n_links": last("link_start"),
        "n_boxes": last("box_start"),
        "n_obs": last("obs_start"),
        "n_excl": last("excl_start"),
        "trace_capacity": int(arrays["trace_t"].shape[1]),
        "link_f32": int(bool(settings["link_f32"])),
    }


def check_settings(settings: Mapping[str, Any]) -> None:
    """Check that ``settings`` holds exactly :data:`SETTINGS` and valid codes.

    Raises
    ------
    ValueError
        Naming a missing or unknown setting, or a code that is not one of its table's.
    """
    names = [s.name for s in SETTINGS]
    missing = [k for k in names if k not in settings]
    extra = [k for k in settings if k not in names]
    if missing or extra:
        raise ValueError(f"kernel settings: missing {missing}, unknown {extra} "
                         f"(softgym.engine.contract.SETTINGS)")  # fmt: skip
    for key, table in (("model", MODEL), ("actuation_mode", ACTUATION)):
        if settings[key] not in table.as_dict().values():
            raise ValueError(f"kernel setting {key!r} = {settings[key]!r} is not a "
                             f"{table.prefix}_* code {table.as_dict()}")  # fmt: skip


def check_arrays(arrays: Mapping[str, Any], counts: Mapping[str, int]) -> None:
    """Check every kernel array of ``arrays`` against the table: present, dtype, shape.

    Parameters
    ----------
    arrays : mapping of str to ndarray
        The batch's arrays (more than the kernel's may be there).
    counts : mapping of str to int
        As for :func:`expected_shape`.

    Raises
    ------
    ValueError
        Naming the first array that is missing or has the wrong dtype or shape.
    """
    missing = [k for k in KERNEL_ARRAYS if k not in arrays]
    if missing:
        raise ValueError(f"kernel arrays {missing} missing (softgym.engine.contract.ARRAYS)")
    f32 = bool(counts.get("link_f32"))
    for spec in ARRAYS:
        x = arrays[spec.name]
        want = expected_dtype(spec, f32)
        if x.dtype != want:
            raise ValueError(f"kernel array {spec.name!r} has dtype {x.dtype}, the kernel "
                             f"reads {want} ({spec.ctype})")  # fmt: skip
        shape = expected_shape(spec, counts)
        if tuple(x.shape) != shape:
            raise ValueError(f"kernel array {spec.name!r} has shape {tuple(x.shape)}, expected "
                             f"{shape} ({', '.join(map(str, spec.shape))})")  # fmt: skip

"""`SimConfig`: the physical and numerical settings of a simulation."""

from __future__ import annotations

from dataclasses import asdict, dataclass, fields, replace
from typing import Any, Literal

from softgym.exceptions import InvalidParameterError
from softgym.validate import number

__all__ = ["DENSITY_RANGE", "SimConfig", "VOXEL_SIZE_RANGE", "YOUNGS_MODULUS_RANGE"]

# Physical ranges no real robot leaves, and within which every derived quantity
# (mass rho L^3, stiffness E L, time step ~ L sqrt(rho / E)) stays a normal
# double: outside them a time step can round to 0 (a run that never advances)
# or a buffer size to infinity. The seed's tissue (5e6 Pa, 1e6 kg/m^3, 1 cm)
# and bone (5e8 Pa) lie well inside.
#: Young's modulus (Pa): soft gels (~10 Pa) to diamond (~1e12 Pa), with margin.
YOUNGS_MODULUS_RANGE = (1.0, 1e13)
#: Density (kg/m^3): aerogels to 1e3 x the seed's (non-physical) 1e6.
DENSITY_RANGE = (1e-3, 1e9)
#: Voxel edge (m): 0.1 mm to 10 m.
VOXEL_SIZE_RANGE = (1e-4, 10.0)


@dataclass(frozen=True)
class SimConfig:
    """Settings shared by every robot of a :class:`~softgym.engine.Simulation`.

    The defaults are the seed study's (evosoro's ``.vxa`` settings,
    docs/PHYSICS.md): the ``"seed"`` preset.

    Parameters
    ----------
    voxel_size : float
        Lattice dimension L (m), 0.01 in the seed.
    dt_frac : float
        Fraction of the stable time step bound
        ``1 / (2 pi sqrt(max k_axial / m))`` over the robot's links (0.9).
    gravity : float
        Gravitational acceleration (m/s^2) pulling along -z; 0 disables gravity (9.81).
    floor : bool
        Penalty floor at z = 0 with Coulomb friction (True).
    bond_damping : float
        Internal damping ratio of the links, the seed's ``BondDampingZ`` (1.0).
    collision_damping : float
        Damping ratio of floor contact, ``ColDampingZ`` (0.8).
    global_damping : float
        Damping ratio towards rest in the world frame, ``SlowDampingZ`` (0.01).
    init_time : float
        Settling time (s): the sinusoid starts and the fitness reference
        ``cm_init`` is taken after it (1.0).
    model : {"seed", "corotational"}
        The step. ``"seed"``: the seed study's own engine (links measured in
        their first voxel's frame with its small-/large-angle switch,
        finite-difference link damping, its floor and friction, sizes that
        follow the drive one step late, its self-collision schedule), which
        its results came from; checked against that
        engine by ``benchmarks/fidelity_seed.py``. ``"corotational"``:
        softgym's symmetric co-rotational beam (links measured in the
        bisector frame of their two voxels, viscous damping on physical
        rates, a floor that never pulls, only voxels missing a face bond
        collide): mirror-symmetric bodies stay symmetric, energy is never
        created by damping, and it is ~1.5x faster; use it for new work
        that need not match the seed's numbers.
    actuation : {"seed", "symmetric"}
        ``"seed"``: a voxel's size follows ``L (1 + CTE T)`` only while it stays
        within ``[min_scale L, L]``, otherwise it keeps its previous size, so
        muscles only contract (the seed's engine). ``"symmetric"``: muscles
        expand and contract (newer Voxelyze), sizes floored at ``min_scale L``.
    min_scale : float
        Smallest actuated size as a fraction of L (0.1, the seed's MinTempFact).
    max_strain : float
        A link whose engineering strain magnitude exceeds this flags its robot
        as diverged (100, the seed's threshold).
    trace_interval : float
        Seconds between centre-of-mass samples of the rollout (0.1: the seed's
        obstacle runs; its novelty runs use 0.5).
    self_collision : bool
        Contact between surface voxels (missing a face bond; interior voxels
        are shielded by their neighbours) of one robot that are more than
        ``collision_exclusion`` bond hops apart (the seed's law: spherical
        envelopes of diameter 1.5 voxels, penalty stiffness ``E L``, no
        damping, no friction). On in the seed's setup (True).
    collision_exclusion : int
        Voxels within this many bond hops never collide (3, the seed's
        ``int(1.5 * CollisionHorizon)``); lattice diagonals would otherwise
        overlap at rest.
    on_divergence : {"flag", "raise"}
        ``"flag"``: a diverged robot is frozen and flagged, the others go on;
        ``"raise"``: :class:`~softgym.exceptions.SimulationDivergedError` is
        raised after the call, naming the first diverged robot.
    friction : float
        Factor (>= 0) on every voxel's static and kinetic friction
        coefficients against the floor and boxes: 0.1 is ice, 3 a grippy,
        muddy ground (1).
    incline : float
        Tilt of the world (degrees, in [-60, 60]) about the y axis: gravity
        gets ``g sin(incline)`` along -x, applied as each voxel's constant
        external force (``Simulation.set_external_force`` replaces it), and
        ``g cos(incline)`` along -z, so +x is uphill (0).
    fluid_drag : float
        ``rho C_d / 2`` (kg/m^3, >= 0) of a fluid around the voxels: each
        exposed face (no bonded neighbour) of area ``s^2`` moving into the
        fluid along its outward normal ``n`` at speed ``v.n > 0`` takes the
        force ``-fluid_drag s^2 (v.n)^2 n`` at its voxel's centre (a face
        moving away takes none). 0: no fluid (0). The seed's voxels weigh
        1e6 kg/m^3, so a fluid of that density with ``C_d = 1`` is 5e5.
    link_precision : {"single", "double"} or None
        Arithmetic of the seed model's link frames and forces. ``"single"``:
        those two passes in float (twice the vector lanes; positions,
        geometry, modes, the world-frame sums and the voxel update stay
        double), with the rotation-vector formula rewritten so that float does
        not cancel (docs/PHYSICS.md, section 5.8); checked against the seed's
        engine by ``benchmarks/fidelity_seed.py``. ``"double"``: the seed's
        engine's own operations in double, as before issue 29 made float the
        default (bit-identical to earlier runs of the same build); needs
        ``model="seed"`` when ``"single"`` is asked for. None (the default):
        ``"single"`` for the seed model, ``"double"`` for the corotational
        one; :attr:`effective_link_precision` tells which.
    """

    voxel_size: float = 0.01
    dt_frac: float = 0.9
    gravity: float = 9.81
    floor: bool = True
    bond_damping: float = 1.0
    collision_damping: float = 0.8
    global_damping: float = 0.01
    init_time: float = 1.0
    model: Literal["seed", "corotational"] = "seed"
    actuation: Literal["seed", "symmetric"] = "seed"
    min_scale: float = 0.1
    max_strain: float = 100.0
    trace_interval: float = 0.1
    self_collision: bool = True
    collision_exclusion: int = 3
    on_divergence: Literal["flag", "raise"] = "flag"
    friction: float = 1.0
    incline: float = 0.0
    fluid_drag: float = 0.0
    link_precision: Literal["double", "single"] | None = None

    def __post_init__(self) -> None:
        def check(name: str, ok: bool, what: str) -> None:
            value = getattr(self, name)
            if not ok:
                raise InvalidParameterError(f"SimConfig.{name} must be {what}, got {value!r}")

        def finite(name: str) -> float:
            # a real number, finite: never a bool, a string ("9.81") or a container
            return number(f"SimConfig.{name}", getattr(self, name))

        lo, hi = VOXEL_SIZE_RANGE
        check("voxel_size", lo <= finite("voxel_size") <= hi, f"in [{lo:g}, {hi:g}] m")
        check("dt_frac", 1e-4 <= finite("dt_frac") <= 10, "in [1e-4, 10]")
        check("gravity", finite("gravity") >= 0, ">= 0 m/s^2 (it pulls along -z)")
        for name in ("bond_damping", "collision_damping", "global_damping"):
            check(name, finite(name) >= 0, ">= 0")
        check("init_time", finite("init_time") >= 0, ">= 0 s")
        check("min_scale", 0 < finite("min_scale") <= 1, "in (0, 1]")
        check("max_strain", finite("max_strain") > 0, "> 0")
        check("trace_interval", finite("trace_interval") > 0, "> 0 s")
        check("model", isinstance(self.model, str) and self.model in ("seed", "corotational"), '"seed" or "corotational"')
        check("actuation", isinstance(self.actuation, str) and self.actuation in ("seed", "symmetric"), '"seed" or "symmetric"')
        check("on_divergence", isinstance(self.on_divergence, str) and self.on_divergence in ("flag", "raise"), '"flag" or "raise"')
        check("friction", finite("friction") >= 0, ">= 0 (a factor on the materials' friction)")
        check("incline", -60 <= finite("incline") <= 60, "in [-60, 60] degrees")
        check("fluid_drag", finite("fluid_drag") >= 0, ">= 0 kg/m^3")
        check("link_precision", self.link_precision is None or (isinstance(self.link_precision, str) and self.link_precision in ("double", "single")), '"single", "double" or None (the model\'s default)')
        if self.link_precision == "single" and self.model != "seed":
            raise InvalidParameterError(
                f'SimConfig.link_precision "single" needs model "seed", got model {self.model!r}'
            )
        check("floor", isinstance(self.floor, (bool, int)), "a bool")
        check("self_collision", isinstance(self.self_collision, (bool, int)), "a bool")
        check(
            "collision_exclusion",
            isinstance(self.collision_exclusion, int) and 1 <= self.collision_exclusion <= 8,
            "an integer in [1, 8]",
        )

    @property
    def effective_link_precision(self) -> Literal["double", "single"]:
        """The link math the step uses: ``link_precision``, or the model's default
        when it is None (``"single"`` for the seed model, ``"double"`` for the
        corotational one, whose links are always double).
        """
        if self.link_precision is not None:
            return self.link_precision
        return "single" if self.model == "seed" else "double"

    @classmethod
    def seed(cls, **overrides: Any) -> SimConfig:
        """The seed study's settings (the defaults), with optional overrides."""
        return cls(**overrides)

    @classmethod
    def corotational(cls, **overrides: Any) -> SimConfig:
        """The seed's settings on softgym's symmetric co-rotational step (see ``model``)."""
        return cls(**{"model": "corotational", **overrides})

    def replace(self, **changes: Any) -> SimConfig:
        """Return a copy with some settings changed (validated)."""
        return replace(self, **changes)

    def to_dict(self) -> dict[str, Any]:
        """Plain-JSON dictionary of the settings."""
        return asdict(self)

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> SimConfig:
        """Inverse of :meth:`to_dict`; unknown keys raise InvalidParameterError."""
        known = {f.name for f in fields(cls)}
        unknown = set(data) - known
        if unknown:
            raise InvalidParameterError(f"unknown SimConfig keys: {sorted(unknown)}")
        return cls(**data)

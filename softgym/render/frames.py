"""Headless RGB frames of voxel robots, in NumPy only (no OpenGL, no matplotlib).

:class:`VoxelRenderer` is a small software rasteriser: every voxel is a rigid
cube (its centre, orientation quaternion and actuated edge length from the
engine), so each face projects, under a fixed orthographic camera that
follows the robot, to a parallelogram. Faces towards the camera that are not
shared with a lattice neighbour are filled with a depth test (a z-buffer, so
large terrain boxes and small voxels never sort wrongly), flat-shaded by
their normal and outlined. The floor is a checkerboard computed per pixel.
:func:`save_gif` writes frames to an animated GIF with Pillow, :func:`save_video`
to an MP4 with imageio and imageio-ffmpeg (the ``video`` extra).
"""

from __future__ import annotations

import contextlib
import math
import os
from collections.abc import Callable, Iterable, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from softgym.exceptions import InvalidParameterError, SoftGymError

if TYPE_CHECKING:  # annotations only: softgym.engine loads compiled code
    from softgym.engine.rollout import Rollout
    from softgym.engine.simulation import Simulation
    from softgym.terrain import Terrain

__all__ = [
    "OBJECT_COLOR",
    "OBSTACLE_COLOR",
    "MissingVideoExtraError",
    "VoxelRenderer",
    "overlay_text",
    "quaternion_to_matrix",
    "render_in_world",
    "render_rollout",
    "save_gif",
    "save_video",
    "simulation_frames",
    "frame_count",
    "FRAME_BUDGET_BYTES",
]


class MissingVideoExtraError(SoftGymError, ImportError):
    """Video output needs the ``video`` extra: ``pip install "softgym[video]"``."""


#: Colour of terrain boxes (the seed's obstacle material, id 5).
OBSTACLE_COLOR = (1.0, 0.784, 0.0)
_DEFAULT_VOXEL_COLOR = (0.6, 0.6, 0.6)

# face f = 2 * axis + (sign > 0): -x, +x, -y, +y, -z, +z
_FACE_AXIS = np.array([0, 0, 1, 1, 2, 2])
_FACE_SIGN = np.array([-1.0, 1.0, -1.0, 1.0, -1.0, 1.0])


def quaternion_to_matrix(q: np.ndarray) -> np.ndarray:
    """Rotation matrices of unit quaternions.

    Parameters
    ----------
    q : ndarray of shape (n, 4), float64
        Quaternions (w, x, y, z).

    Returns
    -------
    ndarray of shape (n, 3, 3), float64
        ``R[i] @ v`` rotates body-frame vectors into the world frame.
    """
    q = np.asarray(q, dtype=np.float64)
    q = q / np.linalg.norm(q, axis=1, keepdims=True)
    w, x, y, z = q.T
    R = np.empty((q.shape[0], 3, 3))
    R[:, 0, 0] = 1 - 2 * (y * y + z * z)
    R[:, 0, 1] = 2 * (x * y - w * z)
    R[:, 0, 2] = 2 * (x * z + w * y)
    R[:, 1, 0] = 2 * (x * y + w * z)
    R[:, 1, 1] = 1 - 2 * (x * x + z * z)
    R[:, 1, 2] = 2 * (y * z - w * x)
    R[:, 2, 0] = 2 * (x * z - w * y)
    R[:, 2, 1] = 2 * (y * z + w * x)
    R[:, 2, 2] = 1 - 2 * (x * x + y * y)
    return R


def _hidden_faces(grid_index: np.ndarray) -> np.ndarray:
    """(n, 6) bool: faces shared with a lattice neighbour (never visible)."""
    gi = np.asarray(grid_index, dtype=np.int64)
    lo = gi.min(axis=0) - 1
    shape = gi.max(axis=0) - lo + 2
    occ = np.zeros(tuple(shape), dtype=bool)
    g = gi - lo
    occ[tuple(g.T)] = True
    out = np.zeros((gi.shape[0], 6), dtype=bool)
    for f in range(6):
        nb = g.copy()
        nb[:, _FACE_AXIS[f]] += int(_FACE_SIGN[f])
        out[:, f] = occ[tuple(nb.T)]
    return out


class VoxelRenderer:
    """Software renderer of one voxel robot and its terrain.

    Parameters
    ----------
    width, height : int
        Frame size in pixels (320 x 240).
    voxel_size : float
        Lattice dimension L (m), to read terrains (voxel lengths) and size the view.
    pixels_per_voxel : float
        Zoom: pixels per voxel length (12: a 6-voxel robot is ~100 px tall
        and the view spans ~26 voxel lengths across).
    azimuth, elevation : float
        Camera direction (degrees): where the camera sits, seen from the
        robot; azimuth from +x towards +y, elevation above the floor.
    light : sequence of 3 floats
        Direction towards the light (world frame).
    outline : float
        Width (pixels) of the dark outline of each face; 0 turns it off.
    """

    def __init__(
        self,
        width: int = 320,
        height: int = 240,
        voxel_size: float = 0.01,
        pixels_per_voxel: float = 12.0,
        azimuth: float = -60.0,
        elevation: float = 30.0,
        light: Sequence[float] = (0.5, -0.3, 1.0),
        outline: float = 0.6,
    ) -> None:
        self.width = int(width)
        self.height = int(height)
        if self.width < 1 or self.height < 1:
            raise InvalidParameterError(f"frame size must be positive, got {width} x {height}")
        self.voxel_size = float(voxel_size)
        if not (math.isfinite(self.voxel_size) and self.voxel_size > 0):
            raise InvalidParameterError(f"voxel_size must be > 0, got {voxel_size}")
        if not (0 < elevation < 90):
            raise InvalidParameterError(f"elevation must be in (0, 90) degrees, got {elevation}")
        self.ppm = float(pixels_per_voxel) / self.voxel_size  # pixels per metre
        az, el = math.radians(azimuth), math.radians(elevation)
        self.to_camera = np.array(
            [math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)]
        )
        fwd = -self.to_camera
        right = np.cross(fwd, [0.0, 0.0, 1.0])
        self.right = right / np.linalg.norm(right)
        self.up = np.cross(self.right, fwd)
        light = np.asarray(light, dtype=np.float64)
        self.light = light / np.linalg.norm(light)
        self.outline = float(outline)
        # floor: the ground point and depth under each pixel centre, for a target at the origin
        xs = (np.arange(self.width) + 0.5 - self.width / 2.0) / self.ppm
        ys = (self.height / 2.0 - (np.arange(self.height) + 0.5)) / self.ppm
        a, b = np.meshgrid(xs, ys)
        s = -(a * self.right[2] + b * self.up[2]) / fwd[2]
        self._gx0 = a * self.right[0] + b * self.up[0] + s * fwd[0]
        self._gy0 = a * self.right[1] + b * self.up[1] + s * fwd[1]
        self._s0 = s
        self._fwd = fwd
        self._proj = np.stack(
            [self.right * self.ppm, -self.up * self.ppm, self.to_camera]
        )  # (3, 3)
        self._hidden_cache: dict[bytes, np.ndarray] = {}

    # -------------------------------------------------------------- floor
    def _floor(self, target: np.ndarray, img: np.ndarray, zbuf: np.ndarray) -> None:
        fwd = self._fwd
        tz = target[2]
        gx = (self._gx0 + target[0] - tz * fwd[0] / fwd[2]) / self.voxel_size
        gy = (self._gy0 + target[1] - tz * fwd[1] / fwd[2]) / self.voxel_size
        zbuf[:] = -(self._s0 - tz / fwd[2])
        tile = 2.0  # voxel lengths per checker square
        checker = (np.floor(gx / tile) + np.floor(gy / tile)) % 2
        shade = 0.86 - 0.07 * checker
        fx = np.abs(gx - np.round(gx))
        fy = np.abs(gy - np.round(gy))
        px = 1.0 / (self.ppm * self.voxel_size)  # one pixel in voxel lengths
        shade = np.where((fx < 0.6 * px) | (fy < 0.6 * px), shade - 0.06, shade)
        img[..., 0] = shade
        img[..., 1] = shade
        img[..., 2] = shade + 0.03

    # -------------------------------------------------------------- faces
    def _faces(
        self,
        origin: np.ndarray,
        e1: np.ndarray,
        e2: np.ndarray,
        color: np.ndarray,
        n1: np.ndarray,
        n2: np.ndarray,
        target: np.ndarray,
        img: np.ndarray,
        zbuf: np.ndarray,
    ) -> None:
        """Fill parallelograms ``origin + a e1 + b e2`` (a, b in [0, 1]) with a depth test.

        ``origin, e1, e2`` : (m, 3) world points/vectors; ``color`` : (m, 3)
        shaded colours; ``n1, n2`` : (m,) grid lines drawn across each face
        (1 = outline only).
        """
        if origin.shape[0] == 0:
            return
        P = self._proj
        o = (origin - target) @ P.T
        o[:, 0] += self.width / 2.0
        o[:, 1] += self.height / 2.0
        u = e1 @ P.T
        v = e2 @ P.T
        det = u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]
        xs = np.stack([o[:, 0], o[:, 0] + u[:, 0], o[:, 0] + v[:, 0], o[:, 0] + u[:, 0] + v[:, 0]])
        ys = np.stack([o[:, 1], o[:, 1] + u[:, 1], o[:, 1] + v[:, 1], o[:, 1] + u[:, 1] + v[:, 1]])
        x0 = np.maximum(np.floor(xs.min(axis=0) - 0.5).astype(np.int64), 0)
        x1 = np.minimum(np.ceil(xs.max(axis=0) + 0.5).astype(np.int64), self.width)
        y0 = np.maximum(np.floor(ys.min(axis=0) - 0.5).astype(np.int64), 0)
        y1 = np.minimum(np.ceil(ys.max(axis=0) + 0.5).astype(np.int64), self.height)
        keep = (np.abs(det) > 1e-6) & (x1 > x0) & (y1 > y0)
        len_u = np.hypot(u[:, 0], u[:, 1])
        len_v = np.hypot(v[:, 0], v[:, 1])
        w = self.outline
        dark = color * 0.55
        for i in np.flatnonzero(keep):
            X = np.arange(x0[i], x1[i]) + 0.5 - o[i, 0]
            Y = (np.arange(y0[i], y1[i]) + 0.5 - o[i, 1])[:, None]
            inv = 1.0 / det[i]
            a = (X * v[i, 1] - Y * v[i, 0]) * inv
            b = (Y * u[i, 0] - X * u[i, 1]) * inv
            inside = (a >= 0.0) & (a <= 1.0) & (b >= 0.0) & (b <= 1.0)
            depth = o[i, 2] + a * u[i, 2] + b * v[i, 2]
            zb = zbuf[y0[i] : y1[i], x0[i] : x1[i]]
            mask = inside & (depth > zb)
            if not mask.any():
                continue
            zb[mask] = depth[mask]
            region = img[y0[i] : y1[i], x0[i] : x1[i]]
            if w > 0:
                hu = abs(det[i]) / len_v[i] / n1[i]  # pixels between lines across e1
                hv = abs(det[i]) / len_u[i] / n2[i]
                fa = a * n1[i]
                fb = b * n2[i]
                da = np.abs(fa - np.round(fa)) * hu
                db = np.abs(fb - np.round(fb)) * hv
                edge = mask & ((da < w) | (db < w))
                region[mask & ~edge] = color[i]
                region[edge] = dark[i]
            else:
                region[mask] = color[i]

    def _shade(self, normals: np.ndarray, base: np.ndarray) -> np.ndarray:
        lam = np.clip(normals @ self.light, 0.0, 1.0)
        return base * (0.45 + 0.55 * lam)[:, None]

    def _terrain_faces(self, terrain: Terrain, target: np.ndarray, img, zbuf) -> None:
        boxes = terrain.as_array(self.voxel_size)
        if boxes.shape[0] == 0:
            return
        origins, e1s, e2s, normals, n1s, n2s = [], [], [], [], [], []
        for f in range(6):
            k, s = int(_FACE_AXIS[f]), _FACE_SIGN[f]
            n = np.zeros(3)
            n[k] = s
            if n @ self.to_camera <= 0 or f == 4:  # back faces and bottoms
                continue
            a, b = (k + 1) % 3, (k + 2) % 3
            lo, hi = boxes[:, :3], boxes[:, 3:]
            o = lo.copy()
            if s > 0:
                o[:, k] = hi[:, k]
            e1 = np.zeros_like(o)
            e2 = np.zeros_like(o)
            e1[:, a] = hi[:, a] - lo[:, a]
            e2[:, b] = hi[:, b] - lo[:, b]
            origins.append(o)
            e1s.append(e1)
            e2s.append(e2)
            normals.append(np.tile(n, (o.shape[0], 1)))
            n1s.append(np.maximum(np.round(e1[:, a] / self.voxel_size), 1.0))
            n2s.append(np.maximum(np.round(e2[:, b] / self.voxel_size), 1.0))
        if not origins:
            return
        normals_a = np.concatenate(normals)
        color = self._shade(normals_a, np.tile(np.asarray(OBSTACLE_COLOR), (normals_a.shape[0], 1)))
        self._faces(
            np.concatenate(origins),
            np.concatenate(e1s),
            np.concatenate(e2s),
            color,
            np.concatenate(n1s),
            np.concatenate(n2s),
            target,
            img,
            zbuf,
        )

    # ------------------------------------------------------------- public
    def render(
        self,
        positions: np.ndarray,
        orientations: np.ndarray | None = None,
        scales: np.ndarray | float | None = None,
        colors: np.ndarray | Sequence[float] | None = None,
        grid_index: np.ndarray | None = None,
        terrain: Terrain | None = None,
        target: Sequence[float] | None = None,
    ) -> np.ndarray:
        """Draw one robot.

        Parameters
        ----------
        positions : ndarray of shape (n_voxels, 3), float64
            Voxel centres (m).
        orientations : ndarray of shape (n_voxels, 4), optional
            Quaternions (w, x, y, z); identity if None.
        scales : ndarray of shape (n_voxels,) or float, optional
            Edge lengths (m); ``voxel_size`` if None.
        colors : ndarray of shape (n_voxels, 3) or (3,), optional
            RGB in [0, 1] (grey if None).
        grid_index : ndarray of shape (n_voxels, 3), int, optional
            Lattice indices: faces shared by neighbours are skipped (faster).
        terrain : Terrain, optional
            Boxes drawn with the robot (the floor is always drawn).
        target : sequence of 3 floats, optional
            Point the camera looks at (m); the robot's mean position if None.

        Returns
        -------
        ndarray of shape (height, width, 3), uint8
        """
        pos = np.asarray(positions, dtype=np.float64).reshape(-1, 3)
        n = pos.shape[0]
        quat = (
            np.tile([1.0, 0.0, 0.0, 0.0], (n, 1))
            if orientations is None
            else np.asarray(orientations)
        )
        R = quaternion_to_matrix(quat) if n else np.zeros((0, 3, 3))
        if scales is None:
            scale = np.full(n, self.voxel_size)
        else:
            scale = np.broadcast_to(np.asarray(scales, dtype=np.float64), (n,))
        base = np.asarray(_DEFAULT_VOXEL_COLOR if colors is None else colors, dtype=np.float64)
        base = (
            np.broadcast_to(base.reshape(-1, 3), (n, 3)) if base.size == 3 else base.reshape(n, 3)
        )
        tgt = (
            pos.mean(axis=0)
            if target is None and n
            else np.asarray((0.0, 0.0, 0.0) if target is None else target, dtype=np.float64)
        )
        img = np.empty((self.height, self.width, 3), dtype=np.float32)
        zbuf = np.empty((self.height, self.width), dtype=np.float64)
        self._floor(tgt, img, zbuf)
        if terrain is not None:
            self._terrain_faces(terrain, tgt, img, zbuf)
        if n:
            hidden = (
                np.zeros((n, 6), dtype=bool) if grid_index is None else self._hidden(grid_index)
            )
            faces_v, faces_f = [], []
            for f in range(6):
                k, s = int(_FACE_AXIS[f]), _FACE_SIGN[f]
                normal = s * R[:, :, k]
                vis = (normal @ self.to_camera > 0) & ~hidden[:, f]
                idx = np.flatnonzero(vis)
                faces_v.append(idx)
                faces_f.append(np.full(idx.size, f))
            vi = np.concatenate(faces_v)
            fi = np.concatenate(faces_f)
            k = _FACE_AXIS[fi]
            a = (k + 1) % 3
            b = (k + 2) % 3
            Rv = R[vi]
            sc = scale[vi][:, None]
            rows = np.arange(vi.size)
            ek = Rv[rows, :, k]
            ea = Rv[rows, :, a] * sc
            eb = Rv[rows, :, b] * sc
            normal = _FACE_SIGN[fi][:, None] * ek
            origin = pos[vi] + 0.5 * sc * normal - 0.5 * ea - 0.5 * eb
            color = self._shade(normal, base[vi])
            ones = np.ones(vi.size)
            self._faces(origin, ea, eb, color, ones, ones, tgt, img, zbuf)
        return (np.clip(img, 0.0, 1.0) * 255.0 + 0.5).astype(np.uint8)

    def _hidden(self, grid_index: np.ndarray) -> np.ndarray:
        gi = np.ascontiguousarray(grid_index, dtype=np.int64)
        key = gi.tobytes()
        hit = self._hidden_cache.get(key)
        if hit is None:
            if len(self._hidden_cache) > 64:
                self._hidden_cache.clear()
            hit = self._hidden_cache[key] = _hidden_faces(gi)
        return hit


def render_rollout(
    rollout: Rollout,
    robot: int = 0,
    renderer: VoxelRenderer | None = None,
    colors: np.ndarray | Sequence[float] | None = None,
    terrain: Terrain | None = None,
) -> np.ndarray:
    """A frame of one robot's final pose in a :class:`~softgym.engine.Rollout`.

    A rollout keeps only the final voxel state (no per-frame history), so
    this gives one still frame; for an animation collect frames while the
    simulation advances (:func:`simulation_frames`, or an env's ``render()``).
    Voxels are drawn at their nominal size (a rollout has no scales).

    Returns
    -------
    ndarray of shape (height, width, 3), uint8
    """
    r = renderer or VoxelRenderer(voxel_size=rollout.voxel_size)
    s = slice(int(rollout.voxel_offsets[robot]), int(rollout.voxel_offsets[robot + 1]))
    return r.render(
        rollout.positions[s],
        rollout.orientations[s],
        None,
        colors,
        grid_index=rollout.grid_index[s],
        terrain=terrain,
    )


#: The colour of a task's movable objects (a box, a cap) in :func:`render_in_world`.
OBJECT_COLOR = (0.55, 0.55, 0.6)


def render_in_world(sim: Any, design: Any, terrain: Terrain, renderer: VoxelRenderer,
                    robot: int = 0) -> np.ndarray:  # fmt: skip
    """A frame of robot ``robot`` of a running :class:`~softgym.engine.Simulation` in its world.

    Its voxels in their materials' colours (``design``'s palette), the world's movable
    objects in :data:`OBJECT_COLOR`, a task's target point (``terrain.meta["target"]``)
    marked with a flat tile that is the figure's, not the world's, and the whole scene
    lifted above the renderer's floor (z = 0) when the world or the robot (one that fell
    off a world without a floor) goes below it; the camera aims at the robot's centre of
    mass.

    Returns
    -------
    ndarray of shape (height, width, 3), uint8
    """
    from softgym.terrain import Box, Terrain

    table = np.zeros((design.palette.max_id + 1, 3))
    for k, mat in design.palette.items():
        table[k] = mat.color[:3]
    colors = table[design.grid[tuple(sim.grid_index(robot).T)]]
    pos, quat, scale = sim.positions(robot), sim.orientations(robot), sim.scales(robot)
    if terrain.objects:
        obj = sim.object_positions(robot)
        pos = np.concatenate([pos, obj])
        quat = np.concatenate([quat, sim.object_orientations(robot)])
        scale = np.concatenate([scale, sim.object_scales(robot)])
        colors = np.concatenate([colors, np.tile(OBJECT_COLOR, (len(obj), 1))])
    target = sim.center_of_mass()[robot]
    name = terrain.name
    if "target" in terrain.meta:
        tx, ty = terrain.meta["target"][:2]
        tile = Box((tx - 0.5, ty - 0.5, 0.0), (tx + 0.5, ty + 0.5, 0.3))
        terrain = Terrain((*terrain.boxes, tile), terrain.floor, name)
    L = sim.config.voxel_size
    low = min(min((b.lo[2] for b in terrain.boxes), default=0.0), float(pos[:, 2].min()) / L)
    if low < 0:
        lift = np.array([0.0, 0.0, -low])
        terrain = Terrain(
            tuple(Box(np.add(b.lo, lift), np.add(b.hi, lift)) for b in terrain.boxes), True, name
        )
        pos = pos + lift * L
        target = target + lift * L
    return renderer.render(pos, quat, scale, colors, terrain=terrain, target=target)


def overlay_text(frame: np.ndarray, lines: Sequence[str]) -> np.ndarray:
    """``frame`` with ``lines`` of text in its top-left corner, dark on a light band.

    Parameters
    ----------
    frame : ndarray of shape (height, width, 3), uint8
    lines : sequence of str

    Returns
    -------
    ndarray of shape (height, width, 3), uint8
        A new frame (the input is not modified).
    """
    from PIL import Image, ImageDraw

    img = Image.fromarray(np.ascontiguousarray(frame, dtype=np.uint8))
    draw = ImageDraw.Draw(img, "RGBA")
    text = "\n".join(lines)
    box = draw.multiline_textbbox((6, 4), text)
    draw.rectangle((box[0] - 3, box[1] - 2, box[2] + 3, box[3] + 2), fill=(255, 255, 255, 190))
    draw.multiline_text((6, 4), text, fill=(20, 20, 20, 255))
    return np.asarray(img)


#: Memory budget (bytes) of the frames one recording may hold:
#: :func:`frame_count` refuses a ``seconds`` x ``fps`` that needs more.
FRAME_BUDGET_BYTES = 2 * 2**30


def frame_count(
    seconds: float,
    fps: float,
    dt: float,
    frame_bytes: int,
    max_bytes: int = FRAME_BUDGET_BYTES,
) -> int:
    """Frames of a recording of ``seconds`` at ``fps``, checked before any is made.

    One frame every ``1 / fps`` simulated seconds, the first before the
    simulation advances: ``floor(seconds fps) + 1`` frames.

    Parameters
    ----------
    seconds : float
        Simulated time (s), finite and >= 0.
    fps : float
        Frames per simulated second, finite, > 0 and at most one per engine
        time step (``1 / dt``): a finer rate would repeat the same state.
    dt : float
        The engine's time step (s).
    frame_bytes : int
        Memory one frame takes (bytes).
    max_bytes : int
        Budget for all frames (bytes); :data:`FRAME_BUDGET_BYTES` by default.

    Returns
    -------
    int
        The number of frames.

    Raises
    ------
    InvalidParameterError
        Naming ``fps`` or ``seconds`` and the accepted range.
    """
    for name, v in (("seconds", seconds), ("fps", fps)):
        if isinstance(v, bool) or not isinstance(v, (int, float, np.integer, np.floating)):
            raise InvalidParameterError(f"{name} must be a number, got {type(v).__name__}")
    if not (math.isfinite(fps) and fps > 0):
        raise InvalidParameterError(f"fps must be finite and > 0, got {fps}")
    if not (math.isfinite(seconds) and seconds >= 0):
        raise InvalidParameterError(f"seconds must be finite and >= 0, got {seconds}")
    if fps * dt > 1.0:
        raise InvalidParameterError(
            f"fps = {fps:g} is finer than the engine's time step ({dt:.3g} s): at most "
            f"{1.0 / dt:.0f} frames per simulated second"
        )
    n = int(math.floor(seconds * fps + 1e-9)) + 1
    if n * frame_bytes > max_bytes:
        raise InvalidParameterError(
            f"seconds x fps = {seconds:g} x {fps:g} gives {n} frames of {frame_bytes} bytes, "
            f"more than the budget of {max_bytes / 2**30:.1f} GiB; lower seconds or fps "
            f"(at most {max(1, max_bytes // max(frame_bytes, 1))} frames)"
        )
    return n


def simulation_frames(
    sim: Simulation,
    seconds: float,
    fps: float = 20.0,
    robot: int = 0,
    renderer: VoxelRenderer | None = None,
    colors: np.ndarray | Sequence[float] | None = None,
    overlay: bool = True,
) -> list[np.ndarray]:
    """Advance ``sim`` by ``seconds`` and return a frame of ``robot`` every ``1 / fps`` s.

    The first frame is the state before advancing. The robot's terrain
    (``sim.terrains[robot]``) is drawn with it. With ``overlay``, each frame
    shows the simulated time (s) and the distance (voxel lengths) of the
    robot's centre of mass, in the floor plane, from where it stood at the
    start.

    Returns
    -------
    list of ndarray of shape (height, width, 3), uint8
    """
    r = renderer or VoxelRenderer(voxel_size=sim.config.voxel_size)
    n = frame_count(seconds, fps, float(np.max(sim.dt)), r.width * r.height * 3) - 1
    terrain = sim.terrains[robot]
    gi = sim.grid_index(robot)
    L = float(sim.config.voxel_size)
    start = sim.center_of_mass()[robot, :2].copy()

    def frame() -> np.ndarray:
        img = r.render(
            sim.positions(robot),
            sim.orientations(robot),
            sim.scales(robot),
            colors,
            grid_index=gi,
            terrain=terrain,
        )
        if not overlay:
            return img
        d = float(np.linalg.norm(sim.center_of_mass()[robot, :2] - start)) / L
        return overlay_text(img, [f"t = {float(sim.time[robot]):5.2f} s", f"d = {d:5.2f} voxels"])

    frames = [frame()]
    for _ in range(n):
        sim.advance(1.0 / fps)
        frames.append(frame())
    return frames


def save_video(
    frames: Iterable[np.ndarray],
    path: str | os.PathLike[str],
    fps: float = 20.0,
    quality: float = 7.0,
) -> int:
    """Write frames to an MP4 (H.264) video through imageio and imageio-ffmpeg.

    Parameters
    ----------
    frames : iterable of ndarray of shape (height, width, 3), uint8
        E.g. :func:`simulation_frames`, or ``env.render()`` frames.
    path : str or path-like
        Output file (``.mp4``); written to a temporary name, then renamed.
    fps : float
        Frames per second.
    quality : float
        imageio's quality, 0-10.

    Returns
    -------
    int
        Number of frames written.

    Raises
    ------
    MissingVideoExtraError
        If imageio or imageio-ffmpeg is missing (``pip install "softgym[video]"``).
    """
    if not (math.isfinite(fps) and fps > 0):
        raise InvalidParameterError(f"fps must be > 0, got {fps}")
    try:
        import imageio.v2 as imageio
        import imageio_ffmpeg  # noqa: F401  (the ffmpeg binary imageio writes with)
    except ImportError as exc:
        raise MissingVideoExtraError(
            f"save_video needs imageio and imageio-ffmpeg ({exc.name} is missing): "
            'pip install "softgym[video]"'
        ) from None
    path = os.fspath(path)
    tmp = f"{path}.tmp{os.getpid()}.mp4"
    n = 0
    try:
        # macro_block_size 1 keeps any frame size (H.264 wants even sizes: pad below)
        with imageio.get_writer(tmp, fps=fps, codec="libx264", quality=quality,
                                macro_block_size=1, pixelformat="yuv420p") as w:  # fmt: skip
            for k, f in enumerate(frames):
                arr = np.asarray(f)
                if arr.ndim != 3 or arr.shape[2] != 3:
                    raise InvalidParameterError(
                        f"frame {k} must have shape (height, width, 3), got {arr.shape}"
                    )
                arr = np.clip(arr, 0, 255).astype(np.uint8)
                h, w_ = arr.shape[:2]
                if h % 2 or w_ % 2:
                    arr = np.pad(arr, ((0, h % 2), (0, w_ % 2), (0, 0)), mode="edge")
                w.append_data(arr)
                n += 1
        if n == 0:  # (the writer opens its file with the first frame: there may be none)
            raise InvalidParameterError("save_video needs at least one frame, got none")
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)  # never leave the temporary file behind
        raise
    return n


def save_gif(
    frames: Iterable[np.ndarray] | Callable[[], Iterable[np.ndarray]] | Rollout | Sequence[Rollout],
    path: str | os.PathLike[str],
    fps: float = 20.0,
    loop: int = 0,
) -> int:
    """Write frames to an animated GIF (Pillow).

    Parameters
    ----------
    frames : iterable of ndarray, callable, Rollout or sequence of Rollout
        ``(height, width, 3)`` uint8 frames (a list, or a generator such as
        ``(env.render() for _ in ...)``); or a callable returning such an
        iterable; or a :class:`~softgym.engine.Rollout` (one still frame of
        robot 0's final pose: a rollout holds no per-frame states) or a
        sequence of rollouts (one frame each, via :func:`render_rollout`).
    path : str or path-like
        Output file; written to a temporary name, then renamed.
    fps : float
        Frames per second of the animation.
    loop : int
        GIF loop count (0: forever).

    Returns
    -------
    int
        Number of frames written.
    """
    from PIL import Image  # Pillow comes with matplotlib

    from softgym.engine.rollout import Rollout

    if not (math.isfinite(fps) and fps > 0):
        raise InvalidParameterError(f"fps must be > 0, got {fps}")
    if isinstance(frames, Rollout):
        frames = [render_rollout(frames)]
    elif callable(frames):
        frames = frames()
    items: list[Any] = list(frames)  # type: ignore[arg-type]
    if items and all(isinstance(f, Rollout) for f in items):
        renderer = VoxelRenderer(voxel_size=items[0].voxel_size)
        items = [render_rollout(f, renderer=renderer) for f in items]
    if not items:
        raise InvalidParameterError("save_gif needs at least one frame")
    images = []
    for k, f in enumerate(items):
        arr = np.asarray(f)
        if arr.ndim != 3 or arr.shape[2] != 3:
            raise InvalidParameterError(
                f"frame {k} must have shape (height, width, 3), got {arr.shape}"
            )
        if arr.dtype != np.uint8:
            arr = np.clip(arr, 0, 255).astype(np.uint8)
        images.append(Image.fromarray(np.ascontiguousarray(arr)))
    path = os.fspath(path)
    tmp = f"{path}.tmp{os.getpid()}.gif"
    images[0].save(
        tmp,
        save_all=True,
        append_images=images[1:],
        duration=max(1, round(1000.0 / fps)),
        loop=loop,
        optimize=False,
    )
    os.replace(tmp, path)
    return len(images)

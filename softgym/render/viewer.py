"""An interactive 3D viewer without a display server: one self-contained HTML file.

:func:`write_viewer` simulates a design, records its voxels every ``1 / fps``
s and writes a plotly figure: the robot's voxels as shaded cubes (their
actuated sizes and orientations, coloured by material), animated over the
rollout with a play button and a time slider, the floor and the terrain's
boxes, and the simulated time and the centre of mass's distance from its
start in the title of every frame. plotly.js is inlined, so the file opens
in any browser without a network (``softgym view RUN_OR_DESIGN``).

:func:`record_voxels` is the recording on its own (plain arrays).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from softgym.render.frames import OBSTACLE_COLOR, frame_count, quaternion_to_matrix

__all__ = ["VoxelRecording", "record_voxels", "viewer_figure", "write_viewer"]

# the 8 corners of a unit cube around its centre, and its 12 triangles
_CORNERS = np.array(
    [
        [-1, -1, -1],
        [1, -1, -1],
        [1, 1, -1],
        [-1, 1, -1],
        [-1, -1, 1],
        [1, -1, 1],
        [1, 1, 1],
        [-1, 1, 1],
    ],
    dtype=np.float64,
)
_TRIANGLES = np.array(
    [
        [0, 1, 2], [0, 2, 3], [4, 6, 5], [4, 7, 6],  # -z, +z
        [0, 5, 1], [0, 4, 5], [3, 2, 6], [3, 6, 7],  # -y, +y
        [0, 3, 7], [0, 7, 4], [1, 5, 6], [1, 6, 2],  # -x, +x
    ],
    dtype=np.int64,
)  # fmt: skip


@dataclass(frozen=True)
class VoxelRecording:
    """A robot's voxels sampled over a rollout.

    Attributes
    ----------
    times : ndarray of shape (n_frames,), float64
        Simulated time of each frame (s).
    positions : ndarray of shape (n_frames, n_voxels, 3), float64
        Voxel centres (voxel lengths).
    orientations : ndarray of shape (n_frames, n_voxels, 4), float64
        Voxel quaternions (w, x, y, z).
    scales : ndarray of shape (n_frames, n_voxels), float64
        Actuated edge lengths (voxel lengths).
    distance : ndarray of shape (n_frames,), float64
        Distance of the centre of mass, in the floor plane, from where it
        started (voxel lengths).
    colors : ndarray of shape (n_voxels, 3), float64
        RGB of each voxel's material, in [0, 1].
    terrain : Terrain
        The world the robot ran in (boxes in voxel lengths).
    """

    times: np.ndarray
    positions: np.ndarray
    orientations: np.ndarray
    scales: np.ndarray
    distance: np.ndarray
    colors: np.ndarray
    terrain: Any


def record_voxels(
    design: Any,
    seconds: float = 5.0,
    fps: float = 10.0,
    task: Any = "flat",
    config: Any = None,
) -> VoxelRecording:
    """Simulate ``design`` in ``task`` and sample its voxels ``fps`` times per simulated second.

    Parameters
    ----------
    design : RobotDesign
    seconds : float
        Simulated time (s).
    fps : float
        Frames per simulated second.
    task : str, Terrain, path or Task
        The world (:func:`softgym.tasks.get_task`).
    config : SimConfig, optional
        Engine settings (default the task's).

    Returns
    -------
    VoxelRecording
    """
    from softgym.engine import Simulation
    from softgym.tasks import get_task

    task = get_task(task)
    cfg = task.config() if config is None else config
    terrain = task.terrain_for(design.shape)
    sim = Simulation([design], config=cfg, terrain=terrain)
    # positions (3), orientations (4), sizes (1) of every voxel, float64, per frame
    n = frame_count(seconds, fps, float(sim.dt[0]), 8 * 8 * sim.n_voxels) - 1
    L = float(cfg.voxel_size)
    gi = sim.grid_index(0)
    grid = np.asarray(design.grid)
    colors = np.array([design.palette[int(m)].color[:3] for m in grid[tuple(gi.T)]])
    start = sim.center_of_mass()[0, :2].copy()
    times, pos, quat, scale, dist = [], [], [], [], []
    for k in range(n + 1):
        if k:
            sim.advance(1.0 / fps)
        times.append(float(sim.time[0]))
        pos.append(sim.positions(0) / L)
        quat.append(sim.orientations(0))
        scale.append(sim.scales(0) / L)
        dist.append(float(np.linalg.norm(sim.center_of_mass()[0, :2] - start)) / L)
    return VoxelRecording(
        times=np.array(times),
        positions=np.array(pos),
        orientations=np.array(quat),
        scales=np.array(scale),
        distance=np.array(dist),
        colors=colors,
        terrain=terrain,
    )


def _cubes(centres: np.ndarray, quats: np.ndarray, sizes: np.ndarray):
    """Vertices (n*8, 3) and triangles (n*12, 3) of rotated, scaled cubes."""
    R = quaternion_to_matrix(quats)
    local = 0.5 * sizes[:, None, None] * _CORNERS[None, :, :]  # (n, 8, 3)
    verts = centres[:, None, :] + np.einsum("nij,nkj->nki", R, local)
    tri = (_TRIANGLES[None, :, :] + 8 * np.arange(len(centres))[:, None, None]).reshape(-1, 3)
    return verts.reshape(-1, 3), tri


def _hex(rgb: np.ndarray) -> list[str]:
    c = np.clip(np.round(np.asarray(rgb) * 255), 0, 255).astype(int)
    return [f"#{r:02x}{g:02x}{b:02x}" for r, g, b in c]


def _robot_mesh(rec: VoxelRecording, k: int, face_colors: list[str]) -> dict[str, Any]:
    verts, tri = _cubes(rec.positions[k], rec.orientations[k], rec.scales[k])
    v = verts.astype(np.float32)  # half the file; far below a pixel's precision
    return {
        "type": "mesh3d", "x": v[:, 0], "y": v[:, 1], "z": v[:, 2],
        "i": tri[:, 0], "j": tri[:, 1], "k": tri[:, 2], "facecolor": face_colors,
        "flatshading": True, "name": "robot", "hoverinfo": "skip",
        "lighting": {"ambient": 0.55, "diffuse": 0.8, "specular": 0.05},
    }  # fmt: skip


def _title(rec: VoxelRecording, k: int, name: str) -> str:
    return f"{name}: t = {rec.times[k]:.2f} s, distance {rec.distance[k]:.2f} voxel lengths"


def viewer_figure(rec: VoxelRecording, name: str = "softgym") -> Any:
    """The plotly figure of a recording (robot animated, floor, terrain, slider, play)."""
    import plotly.graph_objects as go

    face_colors = _hex(np.repeat(rec.colors, 12, axis=0))
    lo = rec.positions.reshape(-1, 3).min(axis=0) - 2.0
    hi = rec.positions.reshape(-1, 3).max(axis=0) + 2.0
    boxes = list(getattr(rec.terrain, "boxes", ()))
    for b in boxes:  # keep boxes near the robot in view
        lo[:2] = np.minimum(lo[:2], np.asarray(b.lo[:2]) - 1.0)
        hi[:2] = np.maximum(hi[:2], np.asarray(b.hi[:2]) + 1.0)
    lo[2] = 0.0
    span = float(max(hi - lo))
    hi = lo + span  # equal axes: voxels look like cubes
    traces: list[Any] = [
        go.Mesh3d(**{k: v for k, v in _robot_mesh(rec, 0, face_colors).items() if k != "type"})
    ]
    if getattr(rec.terrain, "floor", True):
        traces.append(
            go.Mesh3d(
                x=[lo[0], hi[0], hi[0], lo[0]],
                y=[lo[1], lo[1], hi[1], hi[1]],
                z=[0, 0, 0, 0],
                i=[0, 0],
                j=[1, 2],
                k=[2, 3],
                color="#d9d9d9",
                opacity=1.0,
                name="floor",
                hoverinfo="skip",
            )  # fmt: skip
        )
    if boxes:
        c = np.array([(np.asarray(b.lo) + np.asarray(b.hi)) / 2.0 for b in boxes])
        size = np.array([np.asarray(b.hi) - np.asarray(b.lo) for b in boxes])
        verts = c[:, None, :] + 0.5 * size[:, None, :] * _CORNERS[None, :, :]
        tri = (_TRIANGLES[None] + 8 * np.arange(len(boxes))[:, None, None]).reshape(-1, 3)
        v = verts.reshape(-1, 3)
        traces.append(
            go.Mesh3d(
                x=v[:, 0],
                y=v[:, 1],
                z=v[:, 2],
                i=tri[:, 0],
                j=tri[:, 1],
                k=tri[:, 2],
                color=_hex([OBSTACLE_COLOR])[0],
                flatshading=True,
                name="terrain",
                hoverinfo="skip",
            )  # fmt: skip
        )
    frames = [
        go.Frame(
            # only the vertices move: plotly keeps the triangles and colours of trace 0
            data=[
                {k_: v for k_, v in _robot_mesh(rec, k, face_colors).items() if k_ in "type x y z"}
            ],
            traces=[0],
            name=str(k),
            layout={"title": {"text": _title(rec, k, name)}},
        )
        for k in range(len(rec.times))
    ]
    duration = 1000.0 * float(np.diff(rec.times).mean()) if len(rec.times) > 1 else 100.0
    play = {"frame": {"duration": duration, "redraw": True}, "fromcurrent": True,
            "transition": {"duration": 0}}  # fmt: skip
    steps = [
        {"method": "animate", "label": f"{t:.2f}",
         "args": [[str(k)], {"mode": "immediate", "frame": {"duration": 0, "redraw": True},
                             "transition": {"duration": 0}}]}
        for k, t in enumerate(rec.times)
    ]  # fmt: skip
    axis = {"showbackground": False, "gridcolor": "#cccccc"}
    fig = go.Figure(data=traces, frames=frames)
    fig.update_layout(
        title={"text": _title(rec, 0, name)},
        scene={
            "xaxis": {**axis, "title": "x (voxel lengths)", "range": [lo[0], hi[0]]},
            "yaxis": {**axis, "title": "y (voxel lengths)", "range": [lo[1], hi[1]]},
            "zaxis": {**axis, "title": "z (voxel lengths)", "range": [lo[2], hi[2]]},
            "aspectmode": "cube",
            "camera": {"eye": {"x": 1.3, "y": -1.5, "z": 0.9}},
        },
        updatemenus=[{
            "type": "buttons", "showactive": False, "x": 0.02, "y": 0.02, "xanchor": "left",
            "buttons": [
                {"label": "Play", "method": "animate", "args": [None, play]},
                {"label": "Pause", "method": "animate",
                 "args": [[None], {"mode": "immediate", "frame": {"duration": 0, "redraw": False}}]},
            ],
        }],
        sliders=[{"active": 0, "x": 0.15, "len": 0.83, "y": 0.02,
                  "currentvalue": {"prefix": "t (s) = "}, "steps": steps}],
        height=640,
        margin={"l": 0, "r": 0, "t": 40, "b": 0},
        showlegend=False,
    )  # fmt: skip
    return fig


def write_viewer(
    design: Any,
    path: str | os.PathLike[str],
    seconds: float = 5.0,
    fps: float = 10.0,
    task: Any = "flat",
    config: Any = None,
    name: str | None = None,
) -> Path:
    """Simulate ``design`` and write the self-contained HTML viewer of its rollout.

    Parameters
    ----------
    design : RobotDesign
    path : path
        Output ``.html`` (plotly.js inlined: opens offline).
    seconds, fps, task, config
        As for :func:`record_voxels`.
    name : str, optional
        Shown in the title (default the file's stem).

    Returns
    -------
    Path
    """
    from softgym.io import atomic_write_text

    rec = record_voxels(design, seconds=seconds, fps=fps, task=task, config=config)
    path = Path(path)
    fig = viewer_figure(rec, name or path.stem)
    html = fig.to_html(include_plotlyjs=True, full_html=True, auto_play=False)
    path.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_text(path, html)
    return path

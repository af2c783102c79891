"""Pictures of robots: headless RGB frames (NumPy only) and animated GIFs.

:class:`VoxelRenderer` draws a robot's deformed voxels and its terrain into an
``(height, width, 3)`` uint8 array without OpenGL or matplotlib; the
environments' ``render_mode="rgb_array"`` uses it. :func:`save_gif` writes
frames (or rollouts) to an animated GIF, :func:`save_video` to an MP4 (the
``video`` extra); :func:`simulation_frames` overlays time and distance;
:func:`write_viewer` writes a self-contained interactive 3D HTML viewer (plotly).
"""

from softgym.render.frames import (
    OBJECT_COLOR,
    OBSTACLE_COLOR,
    MissingVideoExtraError,
    VoxelRenderer,
    overlay_text,
    quaternion_to_matrix,
    render_in_world,
    render_rollout,
    save_gif,
    save_video,
    simulation_frames,
)
from softgym.render.viewer import write_viewer

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
    "write_viewer",
]

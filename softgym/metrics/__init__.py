"""The seed's measures: displacement, MaxXYDist, L coefficient, composition, AMSS novelty.

Functions take a :class:`~softgym.engine.rollout.Rollout` (vectorised over its
robots) or plain arrays (the ``*_from_arrays`` variants). Distances are in
voxel lengths; diverged robots get :data:`WORST_FITNESS`.
"""

from softgym.metrics.fitness import (
    L_TOLERANCE,
    WALK_METRICS,
    WORST_FITNESS,
    WORST_MINIMIZED,
    Composition,
    LCoefficient,
    composition_counts,
    dilute,
    l_coefficient,
    l_coefficient_details,
    l_coefficient_from_arrays,
    l_coefficients_from_arrays,
    max_xy_dist,
    max_xy_dist_from_arrays,
    norm_final_dist,
    norm_final_dist_from_arrays,
    walk_metrics,
    walk_metrics_from_arrays,
)
from softgym.metrics.novelty import (
    NO_TRAJECTORY_NOVELTY,
    NoveltyArchive,
    amss,
    amss_matrix,
    novelty_scores,
    similarity_matrix,
    traces_from_rollout,
    trajectory_vectors,
)
from softgym.metrics.obstacles import crossed_obstacles, final_xy, obstacle_footprint
from softgym.metrics.task_measures import TASK_MEASURES, task_measure, task_measure_from_arrays

__all__ = [
    "L_TOLERANCE",
    "TASK_MEASURES",
    "NO_TRAJECTORY_NOVELTY",
    "WALK_METRICS",
    "WORST_FITNESS",
    "WORST_MINIMIZED",
    "Composition",
    "LCoefficient",
    "NoveltyArchive",
    "amss",
    "amss_matrix",
    "composition_counts",
    "crossed_obstacles",
    "dilute",
    "final_xy",
    "l_coefficient",
    "l_coefficient_details",
    "l_coefficient_from_arrays",
    "l_coefficients_from_arrays",
    "max_xy_dist",
    "max_xy_dist_from_arrays",
    "norm_final_dist",
    "obstacle_footprint",
    "norm_final_dist_from_arrays",
    "novelty_scores",
    "similarity_matrix",
    "traces_from_rollout",
    "trajectory_vectors",
    "task_measure",
    "task_measure_from_arrays",
    "walk_metrics",
    "walk_metrics_from_arrays",
]

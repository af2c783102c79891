"""Figures and videos: compare groups, Pareto front, overlaid frames, MP4, gait sampling."""

import numpy as np
import pytest

from softgym.design import default_walker
from softgym.engine import Simulation
from softgym.render import overlay_text, save_video, simulation_frames
from softgym.render.figures import (
    metric_label,
    plot_compare,
    plot_pareto_front,
    trace_interval_for,
)


def _rows(values):
    return [{"generation": g, "norm_final_dist_best": v} for g, v in enumerate(values)]


def test_plot_compare_groups_seeds_into_a_median_and_band(tmp_path):
    groups = {"a": [_rows([1, 2, 3]), _rows([2, 3, 4]), _rows([3, 4])], "b": [_rows([0, 1])]}
    path = plot_compare(groups, "norm_final_dist", tmp_path / "c.png")
    assert path.stat().st_size > 5000


def test_plot_pareto_front(tmp_path):
    F = np.array([[1.0, 5.0], [2.0, 6.0], [3.0, 1.0], [0.5, 0.5], [np.nan, 1.0]])
    path = plot_pareto_front(F, ["max_xy_dist", "age"], [True, False], tmp_path / "p.png")
    assert path.stat().st_size > 5000
    with pytest.raises(ValueError):
        plot_pareto_front(F[:, :1], ["max_xy_dist"], [True], tmp_path / "q.png")


def test_labels_have_units():
    assert "(voxel lengths)" in metric_label("max_xy_dist")
    assert "(s)" in metric_label("time_max_xy_dist")


def test_trajectory_sampling_resolves_the_gait():
    d = default_walker()
    assert trace_interval_for(d) <= d.controller.period / 20
    assert trace_interval_for(None) == 0.01


def test_frames_overlay_time_and_distance():
    plain = simulation_frames(Simulation([default_walker()]), 0.1, fps=10, overlay=False)
    shown = simulation_frames(Simulation([default_walker()]), 0.1, fps=10)
    assert len(plain) == len(shown) == 2
    diff = np.any(plain[1] != shown[1], axis=2)
    assert diff[:40, :120].any() and not diff[60:].any()  # text in the top-left corner only
    out = overlay_text(plain[0], ["x"])
    assert out.shape == plain[0].shape and out is not plain[0]


def test_save_video_writes_an_mp4(tmp_path):
    pytest.importorskip(
        "imageio_ffmpeg", reason='needs the video extra: pip install "softgym[video]"'
    )
    import imageio.v3 as iio

    frames = [np.full((41, 63, 3), 20 * k, dtype=np.uint8) for k in range(6)]  # odd sizes
    assert save_video(frames, tmp_path / "v.mp4", fps=5) == 6
    back = iio.imread(tmp_path / "v.mp4")
    assert back.shape[0] == 6 and back.shape[1:3] == (42, 64)


def test_save_video_of_no_frames_and_an_empty_trajectory_are_typed_errors(tmp_path):
    # issue 61: no frames was a FileNotFoundError naming a temporary file; a trace with no
    # sample (a run no longer than its settling time) an IndexError in plot_trajectory
    from softgym.exceptions import InvalidParameterError
    from softgym.render.figures import plot_trajectory

    pytest.importorskip(
        "imageio_ffmpeg", reason='needs the video extra: pip install "softgym[video]"'
    )
    with pytest.raises(InvalidParameterError, match="at least one frame"):
        save_video([], tmp_path / "v.mp4")
    with pytest.raises(InvalidParameterError, match="x, y, z, t"):
        plot_trajectory(np.zeros((0, 4)), tmp_path / "t.png")
    assert list(tmp_path.iterdir()) == []  # no file, no temporary file

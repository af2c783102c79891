"""softgym view: a self-contained plotly HTML file, loaded in headless Chromium."""

import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from softgym.design import default_walker
from softgym.exceptions import InvalidParameterError
from softgym.render.frames import frame_count
from softgym.render.viewer import record_voxels, write_viewer

pytest.importorskip("plotly")


def _chromium():
    for name in (os.environ.get("SOFTGYM_CHROMIUM"), "chromium", "chromium-browser",
                 "google-chrome", "google-chrome-stable"):  # fmt: skip
        if name and shutil.which(name):
            return shutil.which(name)
    return None


def test_record_voxels_samples_the_rollout():
    rec = record_voxels(default_walker(), seconds=0.5, fps=4, task="wall")
    assert rec.times.shape == (3,) and np.allclose(rec.times, [0, 0.25, 0.5], atol=1e-3)
    n = rec.colors.shape[0]
    assert rec.positions.shape == (3, n, 3) and rec.scales.shape == (3, n)
    assert rec.distance[0] == 0.0 and rec.terrain.boxes


def test_viewer_html_is_self_contained(tmp_path):
    path = write_viewer(default_walker(), tmp_path / "v.html", seconds=0.4, fps=5, task="wall")
    html = path.read_text()
    assert "<script src=" not in html  # plotly.js inlined: opens offline
    assert '"Play"' in html and "voxel lengths" in html and "t = 0.40 s" in html


def test_viewer_renders_in_headless_chromium(tmp_path):
    exe = _chromium()
    if exe is None:
        pytest.skip("headless Chromium not found (apt-get install chromium; .ci/run does)")
    path = write_viewer(default_walker(), tmp_path / "v.html", seconds=0.4, fps=5, task="wall")
    shot = tmp_path / "viewer.png"
    cmd = [exe, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
           f"--user-data-dir={tmp_path / 'profile'}", "--window-size=1000,700",
           "--virtual-time-budget=8000", f"--screenshot={shot}", path.as_uri()]  # fmt: skip
    try:
        subprocess.run(cmd, check=True, capture_output=True, timeout=180)
    except (subprocess.CalledProcessError, subprocess.TimeoutExpired) as exc:
        pytest.skip(f"headless Chromium could not run here: {exc}")
    from PIL import Image

    img = np.asarray(Image.open(shot).convert("RGB")).astype(int)
    keep = os.environ.get("SOFTGYM_VIEWER_SCREENSHOT")
    if keep:
        Path(keep).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(shot, keep)
    assert img.shape[:2] == (700, 1000)
    assert len(np.unique(img.reshape(-1, 3), axis=0)) > 50  # not blank
    # the walker's materials: cyan tissue on top, green muscle (the WebGL scene was drawn)
    cyan = (img[:, :, 0] < 60) & (img[:, :, 1] > 180) & (img[:, :, 2] > 180)
    green = (img[:, :, 0] < 60) & (img[:, :, 1] > 150) & (img[:, :, 2] < 60)
    assert cyan.sum() > 500 and green.sum() > 500


def test_frame_count_refuses_rates_finer_than_a_step_and_recordings_past_the_budget():
    dt = 6.4e-4
    assert frame_count(5.0, 10.0, dt, 1000) == 51
    with pytest.raises(InvalidParameterError, match="fps = 1e.09 is finer than the engine's time step"):
        frame_count(1.0, 1e9, dt, 1000)
    with pytest.raises(InvalidParameterError, match="seconds x fps .* more than the budget"):
        frame_count(1e7, 100.0, dt, 1000)
    with pytest.raises(InvalidParameterError, match="fps must be a number"):
        frame_count(1.0, True, dt, 1000)
    with pytest.raises(InvalidParameterError, match="seconds must be finite"):
        frame_count(float("inf"), 10.0, dt, 1000)
    assert frame_count(1.0, 10.0, dt, 1000, max_bytes=11_000) == 11  # the budget is explicit


def test_the_viewer_refuses_a_billion_frames_in_one_line():
    # issue 31: `softgym view good.json --fps 1e9 --seconds 1` crashed (exit 139)
    with pytest.raises(InvalidParameterError, match="finer than the engine's time step"):
        record_voxels(default_walker(), seconds=1.0, fps=1e9)

"""The cost guard's memory estimate and the layout's linear build (issue 61, item 10)."""

import subprocess
import sys
import tracemalloc
from pathlib import Path

import numpy as np
import pytest
from engine_builders import reference_robot, two_material_body

from softgym.engine import Body, SimConfig, Simulation
from softgym.engine.layout import _hop_neighbours, build_layout, memory_estimate
from softgym.terrain import Block, Terrain

BENCH_MEMORY = Path(__file__).resolve().parents[2] / "benchmarks" / "bench_memory.py"


def _hop_neighbours_before(n, v1, v2, hops):
    # the implementation before issue 61 (one search over every row's pairs at once:
    # superlinear, 20 s for 125k voxels), kept as the reference of the chunked one
    src = np.concatenate([v1, v2]).astype(np.int64)
    dst = np.concatenate([v2, v1]).astype(np.int64)
    order = np.argsort(src, kind="stable")
    adj_start = np.concatenate([[0], np.cumsum(np.bincount(src, minlength=n))])
    adj = dst[order]
    reach = np.arange(n, dtype=np.int64) * (n + 1)
    frontier = reach
    for _ in range(hops):
        a, b = np.divmod(frontier, n)
        deg = adj_start[b + 1] - adj_start[b]
        rep_a = np.repeat(a, deg)
        offs = np.repeat(adj_start[b], deg) + (np.arange(deg.sum()) - np.repeat(np.cumsum(deg) - deg, deg))
        new = np.unique(rep_a * n + adj[offs])
        frontier = np.setdiff1d(new, reach, assume_unique=True)
        reach = np.union1d(reach, frontier)
    a, b = np.divmod(reach, n)
    keep = a != b
    a, b = a[keep], b[keep]
    start = np.concatenate([[0], np.cumsum(np.bincount(a, minlength=n))])
    return start, b


def _links(body):
    lay = build_layout([body], [Terrain.flat()], SimConfig())
    return lay.arrays["pos"].shape[0], lay.arrays["v1"], lay.arrays["v2"]


@pytest.mark.parametrize("hops", [1, 2, 3, 5, 8])
def test_hop_neighbours_equal_the_former_implementation(hops):
    rng = np.random.default_rng(hops)
    graphs = []
    for n, m in ((1, 0), (7, 9), (60, 100), (400, 600)):  # random graphs, repeated edges
        v1, v2 = rng.integers(0, n, m), rng.integers(0, n, m)
        graphs.append((n, v1[v1 != v2], v2[v1 != v2]))
    holes = (rng.random((9, 8, 7)) < 0.6).astype(np.int32)
    graphs += [_links(Body.uniform(np.ones((9, 8, 7)))), _links(Body.uniform(holes))]
    for n, v1, v2 in graphs:
        s0, i0 = _hop_neighbours_before(n, v1, v2, hops)
        s1, i1 = _hop_neighbours(n, v1, v2, hops)
        assert s1.dtype == s0.dtype and i1.dtype == i0.dtype
        assert np.array_equal(s1, s0) and np.array_equal(i1, i0)


def _batches():
    rng = np.random.default_rng(7)
    g = rng.integers(0, 3, size=(7, 6, 5)).astype(np.int32)
    fixed = (rng.random(g.shape) < 0.3).astype(np.int8)
    holes = Body.uniform((rng.random((12, 10, 9)) < 0.7).astype(np.int32))
    objects = Terrain(objects=(Block.box((30.0, 0.5, 0.0), (2, 3, 2)),), name="box")
    fence = Terrain.fence(inner=40, height=1, thickness=1, center=(3, 3))
    mixed = ([reference_robot(5), two_material_body(g, fixed=fixed), holes],
             [objects, fence, Terrain.flat()])
    cube = ([Body.uniform(np.ones((11, 10, 9)))], [Terrain.flat()])
    return [
        (mixed, SimConfig()),
        (mixed, SimConfig(link_precision="double", collision_exclusion=2)),
        (mixed, SimConfig(model="corotational", collision_exclusion=4)),
        (cube, SimConfig(self_collision=False)),
    ]


@pytest.mark.parametrize("case", range(4))
def test_the_estimate_counts_what_the_layout_allocates(case):
    (bodies, terrains), cfg = _batches()[case]
    est = memory_estimate(bodies, terrains, cfg, 1)
    sim = Simulation(bodies, cfg, terrain=terrains, n_threads=1)
    a = sim._a
    assert est["voxels"] == a["pos"].shape[0] and est["links"] == sim.n_links  # exact
    # upper bounds: bond hops >= lattice steps; the boxes' volumes (they may overlap)
    assert est["exclusions"] >= a["excl_idx"].size and est["obstacles"] >= a["obs_rank"].size

    def allocated(v):  # padded link rows and cache-line copies count whole
        while isinstance(v.base, np.ndarray):
            v = v.base
        return v.nbytes

    arrays = sum(allocated(v) for v in a.values())
    per_robot = 4096 * sim.n_robots
    over = 8 * (est["exclusions"] - a["excl_idx"].size) + 40 * (est["obstacles"] - a["obs_rank"].size)
    # exact but for the per-robot allowance (4 KiB a robot) and cache-line alignment
    assert abs(est["arrays"] - over - arrays) <= per_robot + 64 * len(a)
    kept = sum(v.nbytes for v in sim._initial.values()) + sim._grid_index.nbytes
    assert abs(est["kept"] - kept) <= per_robot


def test_the_layout_build_peaks_below_the_estimate():
    # tracemalloc sees NumPy's allocations: the build holds about one copy of the layout
    # (it held two, and the exclusion lists' search ~4 KB a voxel, before issue 61)
    body = Body.uniform(np.ones((24, 24, 24)))
    est = memory_estimate([body], [Terrain.flat()], SimConfig(), 1)
    tracemalloc.start()
    try:
        lay = build_layout([body], [Terrain.flat()], SimConfig())
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert lay.arrays["pos"].shape[0] == 24**3
    assert peak <= est["arrays"] + est["build"]
    assert peak <= 2400 * 24**3


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="ru_maxrss in KiB: Linux")
def test_the_estimate_is_within_25_percent_of_the_measured_peak_rss():
    # each in a fresh interpreter: build a solid cube and step it; its peak RSS less that
    # of one that only imported softgym (benchmarks/bench_memory.py, larger cubes there:
    # 27k to 343k voxels)
    out = subprocess.run([sys.executable, str(BENCH_MEMORY), "--sizes", "20", "26", "32"],
                         capture_output=True, text=True, check=True, timeout=300).stdout  # fmt: skip
    rows = [line.split() for line in out.splitlines() if "^3" in line]
    assert [r[0] for r in rows] == ["20^3", "26^3", "32^3"]
    for r in rows:
        assert 0.75 <= float(r[4]) <= 1.25, r  # the estimate over the measured peak

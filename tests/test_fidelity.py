"""softgym.fidelity: the seed-fidelity protocol's cases, perturbations and data readers."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from softgym.design.robot import RobotDesign
from softgym.exceptions import InvalidDesignError, InvalidParameterError
from softgym.fidelity import (
    PERTURBATION,
    REGIMES,
    case_design,
    cases_from_data,
    check_grid,
    load_evolved,
    perturb,
    perturbed_voxel,
)

DATA = Path(__file__).resolve().parents[1] / "benchmarks" / "data" / "seed_engine"
STRUCTURED = json.loads((DATA / "structured.json").read_text())


@st.composite
def bodies(draw):
    shape = tuple(draw(st.integers(1, 4)) for _ in range(3))
    grid = np.asarray(draw(st.lists(st.integers(0, 4), min_size=int(np.prod(shape)),
                                    max_size=int(np.prod(shape)))), dtype=np.int8).reshape(shape)  # fmt: skip
    if not grid.any():
        grid.flat[0] = 1
    return RobotDesign(grid)


@settings(max_examples=40, deadline=None)
@given(bodies(), st.integers(1, 12), st.text(min_size=1, max_size=8))
def test_a_draw_changes_one_voxels_density_by_the_perturbation(design, draw, name):
    out = perturb(design, draw, name=name)
    voxel = perturbed_voxel(design, draw, name=name)
    assert voxel == perturbed_voxel(design, draw, name=name)  # seeded by the name alone
    changed = np.argwhere(out.grid != design.grid)
    assert [tuple(v) for v in changed] == [voxel]
    old, new = design.palette[int(design.grid[voxel])], out.palette[int(out.grid[voxel])]
    assert new.density == old.density * (1.0 + PERTURBATION)
    assert new.youngs_modulus == old.youngs_modulus and new.cte == old.cte
    assert perturb(design, 0, name=name) is design


def test_draws_one_to_six_perturb_six_different_voxels_of_a_case():
    case = cases_from_data(STRUCTURED)[0]
    voxels = {perturbed_voxel(case, d) for d in range(1, 7)}
    assert len(voxels) == 6


def test_draws_past_six_are_further_perturbations_the_oracle_has_not_run():
    # benchmarks/fidelity_seed.py --first-draw 7 samples softgym on draws 7-9: other voxels
    # than the oracle's six wherever a body has nine or more
    for case in cases_from_data(STRUCTURED):
        n = int(np.count_nonzero(case.design.grid))
        voxels = [perturbed_voxel(case, d) for d in range(1, 10)]
        assert len(set(voxels)) == min(n, 9), case.name
        if n < 9:  # a small body's draws wrap around its voxels
            assert voxels[n] == voxels[0]


def _fidelity_cli(*argv):
    script = Path(__file__).resolve().parents[1] / "benchmarks" / "fidelity_seed.py"
    return subprocess.run([sys.executable, str(script), *argv], capture_output=True, text=True,
                          timeout=120)  # fmt: skip


def test_the_fidelity_benchmark_refuses_a_first_draw_below_one():
    res = _fidelity_cli("--first-draw", "0")
    assert res.returncode == 2
    assert "--first-draw must be >= 1" in res.stderr


def test_a_case_design_carries_its_regimes_controller():
    case = cases_from_data(STRUCTURED)[0]
    for regime, r in REGIMES.items():
        c = case_design(case, regime).controller
        assert (c.temp_amplitude, c.period, c.muscle_cte) == (r["dT"], r["period"], r["cte"])


def test_stored_cases_are_the_grids_the_oracle_ran():
    cases = cases_from_data(STRUCTURED)
    assert len(cases) == len(STRUCTURED["cases"]) == 30
    for case in cases:
        check_grid(case, STRUCTURED["cases"][case.name]["grid"])
    other = STRUCTURED["cases"][cases[1].name]["grid"]
    with pytest.raises(InvalidDesignError, match="differs from the one the oracle ran"):
        check_grid(cases[0], other)


def test_bad_draws_and_nameless_designs_are_refused():
    design = cases_from_data(STRUCTURED)[0].design
    with pytest.raises(InvalidParameterError, match="draw must be an integer >= 0"):
        perturbed_voxel(design, -1, name="x")
    with pytest.raises(InvalidParameterError, match="needs the case name"):
        perturb(design, 1)


def test_load_evolved_gives_every_draws_metric():
    cases, values = load_evolved(DATA / "evolved.json")
    assert cases and all((name, 0) in values for name in cases)
    assert all(np.isnan(v) or v >= 0.0 for v in values.values())


def _fidelity_script():
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
    import fidelity_seed

    return fidelity_seed


def test_the_fidelity_targets_are_judged_on_the_mean_of_the_samples():
    # benchmarks/fidelity_seed.py: softgym's draws split into samples of three; each
    # sample's figures against the oracle's first half, the targets on their mean
    from types import SimpleNamespace

    fs = _fidelity_script()
    rng = np.random.default_rng(0)
    cases = [SimpleNamespace(name=f"c{k}", terrain="flat") for k in range(40)]
    truth = np.exp(rng.normal(0.0, 1.0, len(cases)))
    oracle, ours = {}, {}
    for regime in fs.fc.REGIMES:
        for c, t in zip(cases, truth):
            for d in range(1, 7):  # the oracle's halves: noise around the truth
                oracle[(c.name, regime, d)] = t * np.exp(rng.normal(0.0, 0.3))
            for d in range(1, 10):  # softgym: sample 1 (draws 1-3) far noisier
                ours[(c.name, regime, d)] = t * np.exp(rng.normal(0.0, 3.0 if d <= 3 else 0.3))
    one = fs.compare(cases, oracle, ours, [1, 2, 3])["strong"]
    three = fs.compare(cases, oracle, ours, list(range(1, 10)), per_sample=3)["strong"]
    assert [s["draws"] for s in three["samples"]] == [[1, 2, 3], [4, 5, 6], [7, 8, 9]]
    sp = [s["spearman"] for s in three["samples"]]
    assert sp[0] == pytest.approx(one["softgym_vs_oracle"]["spearman"])
    assert three["softgym_vs_oracle"]["spearman"] == pytest.approx(np.mean(sp))
    assert sp[0] < 0.9 * three["oracle_vs_oracle"]["spearman"] < min(sp[1:])
    # the noisy sample alone misses the rank target; the mean of the three meets it
    assert not one["targets"]["spearman"]
    assert three["targets"]["spearman"] == (np.mean(sp) >= 0.9 * three["oracle_vs_oracle"]["spearman"])
    # a body moved by one engine and left still by the other in any sample misses
    for d in range(1, 10):
        oracle[("c0", "strong", d)] = ours[("c0", "strong", d)] = 5.0
    assert three["targets"]["moved_vs_still"]
    for d in (5, 6):  # sample 2's median of c0: still
        ours[("c0", "strong", d)] = 1e-6
    mixed = fs.compare(cases, oracle, ours, list(range(1, 10)), per_sample=3)["strong"]
    assert [s["moved_vs_still"] for s in mixed["samples"]] == [0, 1, 0]
    assert mixed["softgym_vs_oracle"]["moved_vs_still"] == 1
    assert not mixed["targets"]["moved_vs_still"]


def test_the_fidelity_benchmark_refuses_empty_samples():
    res = _fidelity_cli("--samples", "0")
    assert res.returncode == 2
    assert "--samples and --draws must be >= 1" in res.stderr

"""DesignVector: fixed-length vectors <-> designs, within bounds, for any optimiser."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import softgym
from softgym.design import RobotDesign, default_walker
from softgym.design.vector import DesignVector
from softgym.exceptions import InvalidParameterError

ROOT = Path(__file__).resolve().parents[2]


def test_layout_and_bounds():
    enc = DesignVector(shape=(3, 4, 5))
    assert enc.size == 60 + 3 and enc.lower.shape == enc.upper.shape == (63,)
    assert enc.names[0] == "cell[0,0,0]" and enc.names[-1] == "muscle_cte"
    assert DesignVector(shape=(2, 2, 2), controller=False).size == 8


def test_every_vector_decodes_to_a_connected_robot():
    enc = DesignVector(shape=(4, 4, 4))
    rng = np.random.default_rng(0)
    for _ in range(20):
        d = enc.decode(rng.uniform(-0.5, 1.5, enc.size))  # out of bounds: clipped
        assert d.n_voxels >= 1 and len(d.components()[1]) == 1
    empty = enc.decode(np.zeros(enc.size))
    assert empty.n_voxels == 1


def test_encode_decode_round_trip():
    walker = default_walker()
    enc = DesignVector(shape=walker.shape)
    back = enc.decode(enc.encode(walker))
    assert np.array_equal(back.grid, walker.grid)
    for name in ("temp_amplitude", "period", "muscle_cte"):
        assert getattr(back.controller, name) == pytest.approx(getattr(walker.controller, name))
    with pytest.raises(InvalidParameterError):
        enc.encode(RobotDesign(np.ones((2, 2, 2), dtype=int)))
    with pytest.raises(InvalidParameterError):
        enc.decode(np.zeros(3))


def test_decoded_designs_evaluate_in_one_batch():
    enc = DesignVector(shape=(3, 3, 3))
    X = [enc.random(rng=k) for k in range(3)]
    m = softgym.evaluate([enc.decode(x) for x in X], task="flat", seconds=0.5)
    assert m["norm_final_dist"].shape == (3,)


def test_cma_example_runs(tmp_path):
    pytest.importorskip("cma")
    out = tmp_path / "best.json"
    res = subprocess.run(
        [sys.executable, str(ROOT / "examples" / "cma_design_vector.py"), "--generations", "2",
         "--popsize", "4", "--shape", "3", "3", "3", "--seconds", "0.5", "--out", str(out)],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert res.returncode == 0, res.stderr
    assert "iteration 2" in res.stdout and RobotDesign.load(out).n_voxels > 0


@pytest.mark.parametrize(
    "kwargs",
    [{"shape": None}, {"shape": 5}, {"materials": "ab"}, {"materials": None}, {"materials": 5},
     {"materials": [1.5, 2]}, {"materials": [0, 300]}, {"palette": 5}, {"controller": "x"},
     {"fixed_controller": 5}],
)  # fmt: skip
def test_bad_arguments_are_invalid_parameter_errors(kwargs):
    # issue 61, item 11: TypeError, ValueError or OverflowError tracebacks
    with pytest.raises(InvalidParameterError):
        DesignVector(**kwargs)
    dv = DesignVector(shape=(2, 2, 2))
    for bad in ("abc", [object()] * dv.size):
        with pytest.raises(InvalidParameterError, match="expected a vector of numbers"):
            dv.decode(bad)
    with pytest.raises(InvalidParameterError, match="expected a RobotDesign"):
        dv.encode(5)

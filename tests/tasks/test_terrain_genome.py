"""TerrainGenome: bounds named in errors, vectors and JSON round trips, boxes, mutation, fuzzing."""

import json
import math
import re

import numpy as np
import pytest
from fuzzing import FUZZ  # tests/fuzzing.py
from hypothesis import given
from hypothesis import strategies as st

from softgym.exceptions import InvalidTerrainError, SoftGymError
from softgym.tasks.terrain_genome import TERRAIN_BOUNDS, TERRAIN_GENES, TerrainGenome
from softgym.terrain import Terrain

SHAPE = (4, 4, 4)


def test_flat_builds_nothing_and_features_build_rings():
    assert TerrainGenome.flat().terrain(SHAPE).boxes == ()
    g = TerrainGenome(fence_height=0.5, stair_height=0.3, stair_count=2, gap_width=1.0)
    t = g.terrain(SHAPE)
    heights = sorted({round(b.hi[2], 6) for b in t.boxes})
    assert heights == [0.3, 0.5, 0.6]  # fence, step 1, step 2 and the landing at 0.6
    assert len(t.boxes) == 4 + 8 + 4
    t.validate((0, 0, 0), SHAPE)  # nothing on the robot's start
    bumpy = TerrainGenome(rough_amplitude=1.0, rough_cell=1.0, seed=3).terrain(SHAPE)
    assert 0 < len(bumpy.boxes) <= 96 and max(b.hi[2] for b in bumpy.boxes) <= 1.0
    assert TerrainGenome.from_dict(t.meta["genome"]) == g
    assert Terrain.from_json(t.to_json()) == t


def test_genes_that_build_nothing_share_the_key():
    a = TerrainGenome(fence_height=1.0)
    assert a.key() == TerrainGenome(fence_height=1.0, gap_width=2.0, seed=9, stair_height=0.5).key()
    assert a.key() != TerrainGenome(fence_height=1.1).key()


@pytest.mark.parametrize("name", TERRAIN_GENES)
def test_out_of_range_gene_names_the_field_and_range(name):
    lo, hi, _ = TERRAIN_BOUNDS[name]
    for bad in (hi + 1, lo - 1, math.nan):
        shown = re.escape(f"[{int(lo)}, {int(hi) if hi == int(hi) else hi}]")
        with pytest.raises(InvalidTerrainError, match=rf"{name}.*{shown}"):
            TerrainGenome(**{name: bad})
    with pytest.raises(InvalidTerrainError, match=name):
        TerrainGenome(**{name: True})


def test_vector_and_json_round_trips():
    g = TerrainGenome(0.4, 0.2, 3, 1.5, 0.7, 2.0, 12345)
    v = g.to_vector()
    assert v.shape == (7,) and v.dtype == np.float64
    assert TerrainGenome.from_vector(v) == g
    assert TerrainGenome.from_dict(json.loads(json.dumps(g.to_dict()))) == g
    with pytest.raises(InvalidTerrainError, match="7 numbers"):
        TerrainGenome.from_vector(v[:5])
    with pytest.raises(InvalidTerrainError, match="unknown terrain genome field"):
        TerrainGenome.from_dict({"fence": 1})
    assert TerrainGenome.from_vector([0, 0, 2.4, 0, 0, 1, 7.2]).stair_count == 2


def test_random_and_mutate_stay_in_bounds_and_change_something():
    rng = np.random.default_rng(0)
    g = TerrainGenome.flat()
    for _ in range(200):
        m = g.mutate(rng)
        assert m != g
        for name, (lo, hi, _) in TERRAIN_BOUNDS.items():
            assert lo <= getattr(m, name) <= hi
        g = m if rng.random() < 0.5 else TerrainGenome.random(rng)
    a = [TerrainGenome.random(1) for _ in range(2)]
    assert a[0] == a[1]


_NUMBER = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True, width=64),
    st.integers(-(2**40), 2**40),
    st.booleans(),
    st.text(max_size=3),
    st.none(),
)


@FUZZ
@given(st.lists(_NUMBER, min_size=0, max_size=9))
def test_any_vector_is_a_genome_or_an_invalid_terrain_error(values):
    try:
        g = TerrainGenome.from_vector(values)
    except InvalidTerrainError:
        return
    except SoftGymError as exc:  # pragma: no cover - the wrong subclass
        pytest.fail(f"{type(exc).__name__}: {exc}")
    t = g.terrain(SHAPE)
    t.validate((0, 0, 0), SHAPE)
    assert len(t.boxes) <= 4 + 96 + 12 + 4


@FUZZ
@given(st.dictionaries(st.sampled_from([*TERRAIN_GENES, "x"]), _NUMBER, max_size=8))
def test_any_dict_is_a_genome_or_an_invalid_terrain_error(data):
    try:
        TerrainGenome.from_dict(data)
    except InvalidTerrainError:
        pass

"""Hostile inputs to Terrain and Box: a valid terrain or an InvalidTerrainError, nothing else."""

import json
import math

import numpy as np
import pytest
from fuzzing import FUZZ, outcome  # tests/fuzzing.py
from hypothesis import given
from hypothesis import strategies as st

from softgym.exceptions import InvalidTerrainError
from softgym.terrain import MAX_BOXES, MAX_COORDINATE, Box, Terrain


def doc(**changes):
    d = json.loads(Terrain.fence().to_json())
    d.update(changes)
    return d


# ------------------------------------------------------------------ reproducers of issue 12


@pytest.mark.parametrize(
    "data, needle",
    [
        (doc(boxes=[{"lo": "abc", "hi": [1, 1, 1]}]), "box 0: box corner lo must be a sequence"),
        (doc(boxes=[{"lo": "123", "hi": [4, 4, 4]}]), "box corner lo must be a sequence"),
        (doc(boxes=[{"lo": ["a", 0, 0], "hi": [1, 1, 1]}]), "lo[0] must be a number"),
        (doc(boxes=[{"lo": [True, 0, 0], "hi": [1, 1, 1]}]), "lo[0] must be a number"),
        (doc(boxes=[{"lo": [[0], 0, 0], "hi": [1, 1, 1]}]), "lo[0] must be a number"),
        (doc(boxes=[{"lo": [0, 0, 0], "hi": [1e300, 1, 1]}]), "coordinates must lie in"),
        (doc(boxes=[{"lo": [0, 0, 0], "hi": [1, 1, 1], "x": 1}]), "exactly 'lo' and 'hi'"),
        (doc(boxes=5), "'boxes' must be a list"),
        (doc(boxes=[{"lo": [0, 0, 0], "hi": [1, 1, 1]}] * (MAX_BOXES + 1)), f"at most {MAX_BOXES}"),
        (doc(version=True), "version True"),
        (doc(floor="no"), "floor must be a bool"),
        (doc(name=7), "name must be a str"),
        (doc(meta=[1]), "meta must be a dict"),
        (doc(extra=1), "unknown terrain field"),
    ],
)
def test_issue12_terrain_reproducers_raise_typed_errors(data, needle):
    with pytest.raises(InvalidTerrainError) as exc:
        Terrain.from_dict(data)
    assert needle in str(exc.value)


@pytest.mark.parametrize(
    "text",
    ["[" * 100000 + "]" * 100000, '{"a": ' + "9" * 5000 + "}", b"\xff\xfe\x00", 17, None],
)
def test_deep_huge_or_undecodable_terrain_json_raises_typed_errors(text):
    with pytest.raises(InvalidTerrainError):
        Terrain.from_json(text)


@pytest.mark.parametrize(
    "make, needle",
    [
        (lambda: Box("abc", (1, 1, 1)), "lo must be a sequence of 3 numbers"),
        (lambda: Box((0, 0), (1, 1, 1)), "needs 3 coordinates"),
        (lambda: Terrain(boxes=[(1, 2, 3)]), "(lo, hi) pair"),
        (lambda: Terrain(boxes="ab"), "must be a sequence"),
        (lambda: Terrain.fence(inner="10"), "fence inner must be a number"),
        (lambda: Terrain.fence(center=(1, 2, 3)), "fence center needs 2"),
        (lambda: Terrain.stairs(n_rings=2.5), "n_rings must be an integer"),
        (lambda: Terrain.stairs(n_rings=True), "n_rings must be an integer"),
        (lambda: Terrain.stairs(n_rings=10**9), "n_rings must be an integer in 1..250"),
        (lambda: Terrain.stairs(equal_heights="yes"), "equal_heights must be a bool"),
    ],
)
def test_terrain_builders_are_strict(make, needle):
    with pytest.raises(InvalidTerrainError) as exc:
        make()
    assert needle in str(exc.value)


def test_numpy_corners_and_pairs_still_work():
    t = Terrain.from_boxes([(np.zeros(3), np.ones(3)), Box([1, 1, 1], (2, 2, 2))], floor=np.True_)
    assert t.boxes[0] == Box((0, 0, 0), (1, 1, 1)) and t.floor is True
    assert Terrain.from_json(t.to_json().encode()).boxes == t.boxes


# ------------------------------------------------------------------ properties

SCALARS = (
    st.none()
    | st.booleans()
    | st.integers(min_value=-(2**70), max_value=2**70)
    | st.floats(allow_nan=True, allow_infinity=True)
    | st.floats(-20, 20)
    | st.text(max_size=8)
)
JSON_VALUES = st.recursive(
    SCALARS,
    lambda inner: (
        st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=6), inner, max_size=3)
    ),
    max_leaves=12,
)
CORNERS = st.lists(SCALARS, max_size=4) | st.lists(st.floats(-30, 30), min_size=3, max_size=3)


@st.composite
def terrain_docs(draw):
    d = doc()
    for key in draw(st.lists(st.sampled_from(sorted(d)), max_size=3, unique=True)):
        if draw(st.booleans()):
            del d[key]
        else:
            d[key] = draw(JSON_VALUES)
    if draw(st.booleans()) and isinstance(d.get("boxes"), list) and d["boxes"]:
        k = draw(st.integers(0, len(d["boxes"]) - 1))
        d["boxes"][k] = draw(st.fixed_dictionaries({"lo": CORNERS, "hi": CORNERS}) | JSON_VALUES)
    return d


@FUZZ
@given(terrain_docs())
def test_mutated_terrain_files_give_a_terrain_or_a_typed_error(data):
    text = json.dumps(data, allow_nan=True)
    label = outcome("terrain: mutated JSON", Terrain.from_json, text)
    if label == "valid":
        t = Terrain.from_json(text)
        assert Terrain.from_json(t.to_json()).boxes == t.boxes
        assert np.isfinite(t.as_array(0.01)).all()
        assert all(all(abs(v) <= MAX_COORDINATE for v in b.lo + b.hi) for b in t.boxes)


@FUZZ
@given(st.text(max_size=200) | st.binary(max_size=200))
def test_arbitrary_text_gives_a_terrain_or_a_typed_error(text):
    outcome("terrain: raw text/bytes", Terrain.from_json, text)


@FUZZ
@given(CORNERS | JSON_VALUES, CORNERS | JSON_VALUES)
def test_box_corners_give_a_box_or_a_typed_error(lo, hi):
    label = outcome("terrain: Box(lo, hi)", Box, lo, hi)
    if label == "valid":
        b = Box(lo, hi)
        assert all(s > 0 and math.isfinite(s) for s in b.size)


@FUZZ
@given(
    st.sampled_from(["fence", "stairs"]),
    st.dictionaries(
        st.sampled_from(
            ["inner", "height", "thickness", "center", "n_rings", "step_height", "ring_width"]
        ),
        SCALARS | st.integers(1, 5) | st.lists(st.floats(-5, 5), min_size=2, max_size=2),
        max_size=3,
    ),
)
def test_terrain_builders_give_a_terrain_or_a_typed_error(builder, kwargs):
    fence_keys = {"inner", "height", "thickness", "center"}
    stairs_keys = {"inner", "center", "n_rings", "step_height", "ring_width"}
    keys = fence_keys if builder == "fence" else stairs_keys
    kwargs = {k: v for k, v in kwargs.items() if k in keys}
    outcome(f"terrain: Terrain.{builder}(...)", getattr(Terrain, builder), **kwargs)

"""Hostile inputs to RobotDesign and CPPN loaders: a valid object or a SoftGymError, nothing else.

The reproducers of issue 12 first, then Hypothesis properties over mutated design files,
raw text and grids. ``OUTCOMES`` counts what each property saw (used for the issue's tally).
"""

import json
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest
from fuzzing import FUZZ, outcome  # tests/fuzzing.py
from hypothesis import given
from hypothesis import strategies as st

from softgym.design import CPPN, CompositionRules, Controller, RobotDesign, default_walker
from softgym.design.robot import MAX_GRID_DIM, MAX_GRID_VOXELS, check_grid_shape
from softgym.exceptions import DesignFileError, InvalidDesignError, SoftGymError


def walker_dict(encoding="digits"):
    d = default_walker().to_dict()
    if encoding == "ints":
        d["grid"]["encoding"] = "ints"
        d["grid"]["layers"] = [
            [[int(c) for c in row] for row in layer] for layer in d["grid"]["layers"]
        ]
    return d


# ------------------------------------------------------------------ reproducers of issue 12


def _with(path, value, encoding="digits"):
    d = walker_dict(encoding)
    node = d
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value
    return json.dumps(d)


@pytest.mark.parametrize(
    "text, needle",
    [
        ("[" * 100000 + "]" * 100000, "nested too deeply"),
        ('{"a": ' + "9" * 5000 + "}", "invalid JSON value"),
        (b"\xff\xfe\x00", "not UTF-8"),
        (_with(["palette", 0, "id"], [1]), "'id' must be an integer"),
        (_with(["palette", 0, "id"], 1.0), "'id' must be an integer"),
        (_with(["grid", "layers", 0, 0, 0], 10**30, "ints"), "got 1000000000000000000000000000000"),
        (_with(["grid", "layers", 0, 0, 0], 1.7, "ints"), "got 1.7"),
        (_with(["grid", "layers", 0, 0, 0], True, "ints"), "got True"),
        (_with(["grid", "layers", 0, 0, 0], "1", "ints"), "got '1'"),
        (_with(["grid", "layers", 0, 0, 0], [1, 2], "ints"), "got [1, 2]"),
        (_with(["grid", "layers", 0, 0], [[3] * 6] * 6, "ints"), "got [3, 3, 3, 3, 3, 3]"),
        (_with(["grid", "shape"], [6.5, 6, 6]), "must be 3 integers"),
        (_with(["grid", "shape"], [True, 6, 6]), "must be 3 integers"),
        (_with(["grid", "shape"], "abc"), "must be 3 integers"),
        (_with(["palette", 0, "youngs_modulus"], "5e6"), "must be a number"),
        (_with(["palette", 0, "youngs_modulus"], True), "must be a number"),
        (_with(["palette", 2, "cte"], 10), "cte must lie in [-0.1, 0.1]"),
        (_with(["controller", "period"], True), "must be a number"),
        (_with(["controller", "period"], "0.25"), "must be a number"),
    ],
)
def test_issue12_design_json_reproducers_raise_typed_errors(text, needle):
    with pytest.raises(SoftGymError) as exc:
        RobotDesign.from_json(text)
    assert needle in str(exc.value)


def test_huge_grid_shape_is_refused_before_allocation():
    d = walker_dict()
    d["grid"].update(shape=[100000, 100000, 1], layers=[[]])
    with pytest.raises(InvalidDesignError, match=f"1..{MAX_GRID_DIM}"):
        RobotDesign.from_json(json.dumps(d))
    d["grid"].update(shape=[1000, 1000, 2], layers=[[], []])
    with pytest.raises(InvalidDesignError, match=f"cap of {MAX_GRID_VOXELS}"):
        RobotDesign.from_json(json.dumps(d))
    with pytest.raises(InvalidDesignError, match="cap of"):
        RobotDesign(np.zeros((1000, 1000, 2), dtype=np.int8))


def test_grid_shape_check_is_strict():
    assert check_grid_shape((6, np.int64(6), 1)) == (6, 6, 1)
    for bad in [(6.5, 6, 6), (6.0, 6, 6), (True, 6, 6), ("6", 6, 6), "666", (6, 6), (0, 6, 6), 6]:
        with pytest.raises(InvalidDesignError, match="grid_shape"):
            check_grid_shape(bad, "grid_shape")
    # an int too long for Python to print still gets the typed, short message
    for bad in [(10**5000, 6, 6), (10**5000, 6.5, 6)]:
        with pytest.raises(InvalidDesignError, match="16610-bit integer") as info:
            check_grid_shape(bad, "grid_shape")
        assert len(str(info.value)) < 120


def test_ragged_or_overflowing_grids_raise_typed_errors():
    with pytest.raises(InvalidDesignError, match="3-D"):
        RobotDesign([[[1], [1, 1]]])
    with pytest.raises(InvalidDesignError):
        RobotDesign([[[10**30]]])


@pytest.mark.parametrize(
    "make_path",
    [
        lambda tmp: tmp / "nonexistent.json",
        lambda tmp: tmp,
    ],
)
def test_unreadable_design_files_raise_design_file_error(tmp_path, make_path):
    path = make_path(tmp_path)
    with pytest.raises(DesignFileError, match=str(path)) as exc:
        RobotDesign.load(path)
    assert isinstance(exc.value, OSError) and isinstance(exc.value, InvalidDesignError)


def test_binary_and_malformed_design_files_name_the_file(tmp_path):
    binary = tmp_path / "robot.bin"
    binary.write_bytes(bytes(range(256)) * 4)
    with pytest.raises(DesignFileError, match="not UTF-8"):
        RobotDesign.load(binary)
    bad = tmp_path / "bad.json"
    bad.write_text('{"schema": "softgym.design"')
    with pytest.raises(InvalidDesignError, match="bad.json"):
        RobotDesign.load(bad)
    good = tmp_path / "good.json"
    default_walker().save(good)
    assert RobotDesign.load(good) == default_walker()


def test_allocation_reproducers_under_a_memory_limit():
    # In a child process capped at 3 GiB of address space: the 9-56 GiB grids of the issue
    # must be refused by the size check, not by a MemoryError.
    code = textwrap.dedent(
        """
        import json, re, resource
        resource.setrlimit(resource.RLIMIT_AS, (3 * 2**30, 3 * 2**30))
        from softgym.design import RobotDesign, default_walker, from_vxa, to_vxa
        from softgym.exceptions import InvalidDesignError
        d = default_walker().to_dict()
        d["grid"].update(shape=[100000, 100000, 1], layers=[[]])
        try:
            RobotDesign.from_json(json.dumps(d))
        except InvalidDesignError as exc:
            print("json:", exc)
        x = to_vxa(default_walker())
        x = re.sub("<X_Voxels>6", "<X_Voxels>100000", re.sub("<Y_Voxels>6", "<Y_Voxels>100000", x))
        try:
            from_vxa(x)
        except InvalidDesignError as exc:
            print("vxa:", exc)
        """
    )
    env = {**os.environ, "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"}
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=120, env=env
    )
    assert out.returncode == 0, out.stderr
    assert "json: design 'grid' shape (100000, 100000, 1)" in out.stdout
    assert "vxa: <X_Voxels>, <Y_Voxels>, <Z_Voxels> (100000, 100000, 6)" in out.stdout


# ------------------------------------------------------------------ properties

SCALARS = (
    st.none()
    | st.booleans()
    | st.integers(min_value=-(2**70), max_value=2**70)
    | st.sampled_from([0, 1, 2, 3, 4, 9, 10, 127, 128, -1, 10**30, 1000, 100000])
    | st.floats(allow_nan=True, allow_infinity=True)
    | st.text(max_size=12)
)
JSON_VALUES = st.recursive(
    SCALARS,
    lambda inner: (
        st.lists(inner, max_size=5) | st.dictionaries(st.text(max_size=8), inner, max_size=4)
    ),
    max_leaves=16,
)


def _paths(node, prefix=()):
    yield prefix
    if isinstance(node, dict):
        for k, v in node.items():
            yield from _paths(v, (*prefix, k))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from _paths(v, (*prefix, i))


def _mutate(doc, path, value, delete):
    if not path:
        return value
    node = doc
    for key in path[:-1]:
        node = node[key]
    if delete and isinstance(node, dict):
        del node[path[-1]]
    elif delete and isinstance(node, list):
        node.pop(path[-1])
    else:
        node[path[-1]] = value
    return doc


DOCS = {enc: walker_dict(enc) for enc in ("digits", "ints")}
PATHS = {enc: sorted(_paths(doc), key=repr) for enc, doc in DOCS.items()}


@st.composite
def mutated_designs(draw):
    enc = draw(st.sampled_from(["digits", "ints"]))
    doc = json.loads(json.dumps(DOCS[enc]))
    for _ in range(draw(st.integers(1, 3))):
        paths = sorted(_paths(doc), key=repr)
        path = draw(st.sampled_from(paths))
        doc = _mutate(doc, path, draw(JSON_VALUES), draw(st.booleans()))
        if not isinstance(doc, dict):
            break
    return json.dumps(doc, allow_nan=True)


@FUZZ
@given(mutated_designs())
def test_mutated_design_files_give_a_design_or_a_typed_error(text):
    label = outcome("design: mutated JSON", RobotDesign.from_json, text)
    if label == "valid":
        design = RobotDesign.from_json(text)
        assert RobotDesign.from_json(design.to_json()) == design  # what loads, round-trips


@FUZZ
@given(st.text(max_size=300) | st.binary(max_size=300))
def test_arbitrary_text_gives_a_design_or_a_typed_error(text):
    outcome("design: raw text/bytes", RobotDesign.from_json, text)


GRIDS = (
    st.lists(st.lists(st.lists(SCALARS, max_size=3), max_size=3), max_size=3)
    | st.lists(
        st.lists(st.lists(st.integers(-3, 200), min_size=1, max_size=3), min_size=1, max_size=3),
        min_size=1,
        max_size=3,
    )
    | JSON_VALUES
)


@FUZZ
@given(GRIDS)
def test_arbitrary_grids_give_a_design_or_a_typed_error(grid):
    outcome("design: grid argument", RobotDesign, grid)


@FUZZ
@given(
    st.lists(SCALARS, max_size=4)
    | SCALARS
    | st.tuples(*[st.integers(-2, MAX_GRID_DIM + 2)] * 3)
    | st.lists(st.integers(1, 120), min_size=3, max_size=3)
)
def test_grid_shapes_are_checked_or_refused(shape):
    label = outcome("design: grid shape", check_grid_shape, shape)
    if label == "valid":
        assert all(type(v) is int and 1 <= v <= MAX_GRID_DIM for v in check_grid_shape(shape))


CPPN_DOC = json.loads(CPPN.random(rng=0).to_json())


@st.composite
def mutated_cppns(draw):
    doc = json.loads(json.dumps(CPPN_DOC))
    path = draw(st.sampled_from(sorted(_paths(doc), key=repr)))
    doc = _mutate(doc, path, draw(JSON_VALUES), draw(st.booleans()))
    return json.dumps(doc, allow_nan=True)


@FUZZ
@given(mutated_cppns())
def test_mutated_cppn_files_give_a_cppn_or_a_typed_error(text):
    label = outcome("cppn: mutated JSON", CPPN.from_json, text)
    if label == "valid":
        g = CPPN.from_json(text)
        outcome("cppn: to_grid of a loaded CPPN", g.to_grid, (3, 3, 3))


def test_controller_from_design_is_strict():
    with pytest.raises(SoftGymError, match="must be a number"):
        Controller.clipped(period=[1])


@FUZZ
@given(
    st.tuples(*[st.integers(1, 9)] * 3).flatmap(
        lambda shape: st.lists(
            st.booleans(), min_size=int(np.prod(shape)), max_size=int(np.prod(shape))
        ).map(lambda bits: np.array(bits, dtype=bool).reshape(shape))
    )
)
def test_union_find_labels_equal_the_table_walk(mask):
    from softgym.design import robot

    walked = robot.label_components(mask)  # small: the cached table walk
    joined = robot._label_components_union_find(mask)  # what grids over 4096 cells use
    assert np.array_equal(walked[0], joined[0]) and walked[1] == joined[1]


def test_large_designs_are_labelled_without_a_per_voxel_table():
    grid = np.ones((100, 100, 100), dtype=np.int8)
    grid[50, :, :] = 0  # two slabs
    design = RobotDesign(grid)
    assert design.violations(CompositionRules()) == [
        "connected: the voxels form 2 separate 6-connected bodies (sizes [500000, 490000]); "
        "use largest_component()"
    ]

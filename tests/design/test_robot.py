import json
import os

import numpy as np
import pytest
from fuzzing import fifo_code, refused_in_child

from softgym.design.controller import Controller
from softgym.design.material import Material, Palette, default_palette
from softgym.design.robot import (
    DESIGN_VERSION,
    CompositionRules,
    RobotDesign,
    default_walker,
    label_components,
    largest_component_mask,
)
from softgym.engine.body import Body
from softgym.exceptions import InvalidDesignError


def block(shape=(6, 6, 6), fill=3, upto=None):
    g = np.zeros(shape, dtype=np.int8)
    g.reshape(-1)[: (g.size if upto is None else upto)] = fill
    return g


# ---------------------------------------------------------------- construction


@pytest.mark.parametrize(
    "grid, needle",
    [
        (np.ones((6, 6), dtype=int), "3-D"),
        (np.ones((6, 0, 6), dtype=int), "empty dimension"),
        (np.ones((2, 2, 2)), "integer"),
        (np.ones((2, 2, 2), dtype=bool), "integer"),
        (np.full((2, 2, 2), -1), "0..127"),
        (np.full((2, 2, 2), 200), "0..127"),
        (np.full((2, 2, 2), 12), "palette lacks"),
    ],
)
def test_construction_rejects_bad_grids(grid, needle):
    with pytest.raises(InvalidDesignError, match=needle):
        RobotDesign(grid)


def test_grid_is_readonly_int8_copy():
    g = block(upto=100)
    d = RobotDesign(g)
    g[0, 0, 0] = 0
    assert d.grid[0, 0, 0] == 3
    assert d.grid.dtype == np.int8 and d.grid.flags.c_contiguous
    with pytest.raises(ValueError):
        d.grid[0, 0, 0] = 1


def test_controller_sets_muscle_cte_of_materials_3_and_4():
    d = RobotDesign(block(upto=100), controller=Controller(muscle_cte=0.03))
    assert d.palette[3].cte == 0.03 and d.palette[4].cte == -0.03
    assert d.palette[8].cte == 0.05  # evolvable materials are not the controller's
    e = d.with_controller(Controller(muscle_cte=0.002))
    assert e.palette[3].cte == 0.002 and e.palette[4].cte == -0.002
    # a palette without 3 or 4 is left alone
    p = Palette({1: Material("soft", 5e6)})
    assert RobotDesign(np.ones((2, 2, 2), dtype=int), palette=p).palette == p


def test_counts_and_equality():
    g = np.zeros((3, 3, 3), dtype=np.int8)
    g[0, :, 0] = 3
    g[1, :, 0] = 2
    g[2, 0, 0] = 4
    d = RobotDesign(g)
    assert d.n_voxels == 7 and d.shape == (3, 3, 3)
    assert d.material_counts() == {2: 3, 3: 3, 4: 1}
    assert d.count((3, 4)) == 4 and d.count(2) == 3
    assert d == RobotDesign(g.astype(np.int64))
    assert d != d.replace(controller=Controller(period=0.5))
    with pytest.raises(InvalidDesignError, match="unknown RobotDesign field"):
        d.replace(colour=1)


# ---------------------------------------------------------------- connectivity


def test_label_components_orders_by_first_voxel():
    m = np.zeros((4, 1, 1), dtype=bool)
    m[[0, 2, 3], 0, 0] = True
    labels, sizes = label_components(m)
    assert labels[:, 0, 0].tolist() == [1, 0, 2, 2]
    assert sizes == [1, 2]
    # diagonal neighbours are not connected (6-connectivity)
    d = np.zeros((2, 2, 2), dtype=bool)
    d[0, 0, 0] = d[1, 1, 0] = d[1, 1, 1] = True
    assert label_components(d)[1] == [1, 2]


def test_largest_component_keeps_biggest_and_breaks_ties_like_the_seed():
    g = np.zeros((5, 5, 1), dtype=np.int8)
    g[0, 0:2, 0] = 1  # size 2, first in C order
    g[4, 0:3, 0] = 3  # size 3
    g[2, 2, 0] = 4  # size 1
    d = RobotDesign(g)
    assert not d.is_connected()
    kept = d.largest_component()
    assert kept.material_counts() == {3: 3}
    assert kept.is_connected()
    tie = np.zeros((5, 1, 1), dtype=bool)
    tie[[0, 1, 3, 4], 0, 0] = True
    assert largest_component_mask(tie)[:, 0, 0].tolist() == [True, True, False, False, False]
    assert not largest_component_mask(np.zeros((2, 2, 2), bool)).any()


# ---------------------------------------------------------------- validity rules


def test_seed_rules_thresholds():
    rules = CompositionRules.seed()
    assert RobotDesign(block(upto=65)).is_valid(rules)  # 65 >= 30 % of 216 = 64.8
    with pytest.raises(InvalidDesignError, match=r"min_filled_fraction: 64 filled voxels of 216"):
        RobotDesign(block(upto=64)).validate(rules)
    g = block(upto=100, fill=1)
    g.reshape(-1)[:21] = 3  # 21 muscle < 21.6
    with pytest.raises(InvalidDesignError, match=r"min_muscle_fraction_of_grid: 21 muscle voxels"):
        RobotDesign(g).validate()
    g.reshape(-1)[21] = 9  # 22 with a new muscle
    assert RobotDesign(g).validate() is not None


def test_rules_name_every_failure():
    with pytest.raises(InvalidDesignError, match="non_empty"):
        RobotDesign(np.zeros((6, 6, 6), dtype=np.int8)).validate(CompositionRules())
    g = block(upto=100)
    g[5, 5, 5] = 3
    with pytest.raises(
        InvalidDesignError, match=r"connected: the voxels form 2 separate.*\[100, 1\]"
    ):
        RobotDesign(g).validate(CompositionRules())
    assert RobotDesign(g).validate(CompositionRules(require_connected=False))
    tiny = np.zeros((6, 6, 6), dtype=np.int8)
    tiny[0, 0, 0] = 1
    problems = RobotDesign(tiny).violations(CompositionRules.seed())
    assert [p.split(":")[0] for p in problems] == [
        "min_filled_fraction",
        "min_muscle_fraction_of_grid",
    ]


def test_obstacle_rules():
    rules = CompositionRules.obstacles()
    g = block(upto=100, fill=3)
    msg = str(pytest.raises(InvalidDesignError, RobotDesign(g).validate, rules).value)
    assert "min_tissue_fraction_of_filled: 0 tissue voxels of 100" in msg
    assert "min_bone_voxels: 0 bone voxels, needs >= 1" in msg
    g.reshape(-1)[:10] = 1  # 10 % tissue of filled, no bone yet
    assert [p.split(":")[0] for p in RobotDesign(g).violations(rules)] == ["min_bone_voxels"]
    g.reshape(-1)[0] = 2
    RobotDesign(g).validate(rules)
    g.reshape(-1)[:91] = 1  # 9 muscle of 100 filled
    with pytest.raises(InvalidDesignError, match="min_muscle_fraction_of_filled: 9 muscle"):
        RobotDesign(g).validate(rules)


def test_rules_dict_roundtrip():
    r = CompositionRules.obstacles()
    assert CompositionRules.from_dict(json.loads(json.dumps(r.to_dict()))) == r


# ---------------------------------------------------------------- engine body


def test_to_body_tables_follow_ids():
    d = default_walker().with_controller(
        Controller(temp_amplitude=9.0, period=0.4, muscle_cte=0.02)
    )
    b = d.to_body(origin=(0.1, 0.0, 0.0))
    assert isinstance(b, Body)
    assert b.youngs_modulus.shape == (10,)
    assert b.youngs_modulus[0] == 0.0
    assert b.youngs_modulus[2] == 5e8 and b.youngs_modulus[5] == 5e9
    assert b.cte[3] == 0.02 and b.cte[4] == -0.02 and b.cte[8] == 0.05
    assert (b.density[1:] == 1e6).all() and (b.poisson[1:] == 0.35).all()
    assert (b.phase == 0).all()
    assert (b.temp_amplitude, b.period) == (9.0, 0.4)
    assert b.origin.tolist() == [0.1, 0.0, 0.0]
    assert np.array_equal(b.grid, d.grid)
    assert b.n_voxels == d.n_voxels


def test_default_walker():
    w = default_walker()
    w.validate(CompositionRules.seed())
    assert w.shape == (6, 6, 6) and w.n_voxels == 216 and w.is_connected()
    assert w.material_counts() == {1: 36, 3: 60, 4: 120}
    # uneven counter-phase split (front third Active_+, rear two thirds Active_-), passive top
    assert (w.grid[:2, :, :5] == 3).all() and (w.grid[2:, :, :5] == 4).all()
    assert (w.grid[:, :, 5] == 1).all()
    assert w.controller == Controller()


# ---------------------------------------------------------------- JSON


def test_json_roundtrip_is_exact(tmp_path):
    pal = (
        default_palette().with_changes(8, density=123456.789, cte=0.0123456789).with_counterphase()
    )
    d = RobotDesign(default_walker().grid, palette=pal, controller=Controller(13.3, 0.123, 0.0311))
    text = d.to_json()
    data = json.loads(text)
    assert data["schema"] == "softgym.design" and data["version"] == DESIGN_VERSION
    assert data["grid"]["layers"][0][0] == "334444"  # layers[z][y] is a row along x
    assert data["grid"]["layers"][5][3] == "111111"
    assert RobotDesign.from_json(text) == d
    d.save(tmp_path / "walker.json")
    assert RobotDesign.load(tmp_path / "walker.json") == d
    assert not list(tmp_path.glob("*.tmp*"))


def test_json_ids_above_nine():
    pal = Palette({1: Material("a", 5e6), 12: Material("b", 6e6)})
    g = np.ones((2, 2, 1), dtype=np.int8)
    g[1, 1, 0] = 12
    d = RobotDesign(g, palette=pal)
    data = d.to_dict()
    assert data["grid"]["encoding"] == "ints"
    assert data["grid"]["layers"][0][1] == [1, 12]
    assert RobotDesign.from_json(d.to_json()) == d


def test_json_version_and_malformed_files():
    data = default_walker().to_dict()
    with pytest.raises(InvalidDesignError, match="version 2 is newer than this softgym reads"):
        RobotDesign.from_dict({**data, "version": 2})
    with pytest.raises(InvalidDesignError, match="invalid version"):
        RobotDesign.from_dict({**data, "version": "1"})
    with pytest.raises(InvalidDesignError, match="not a softgym design"):
        RobotDesign.from_dict({**data, "schema": "other"})
    with pytest.raises(InvalidDesignError, match="not valid JSON"):
        RobotDesign.from_json("{'grid': ")
    with pytest.raises(InvalidDesignError, match="no 'controller'"):
        RobotDesign.from_dict({k: v for k, v in data.items() if k != "controller"})
    bad = json.loads(json.dumps(data))
    bad["grid"]["layers"][2][1] = "33x333"
    with pytest.raises(InvalidDesignError, match="row z=2 y=1 must be 6 digits"):
        RobotDesign.from_dict(bad)
    bad["grid"]["layers"] = bad["grid"]["layers"][:5]
    with pytest.raises(InvalidDesignError, match="5 layers, shape says nz = 6"):
        RobotDesign.from_dict(bad)


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs on this platform")
@pytest.mark.parametrize(
    "load",
    ["from softgym.design import RobotDesign as R; R.load",
     "from softgym.design.vxa import load_vxa; load_vxa"],
)  # fmt: skip
def test_a_fifo_given_as_a_design_file_is_refused_at_once(tmp_path, load):
    # a FIFO with no writer blocks a plain open() forever: the child would hang
    fifo = tmp_path / "robot.json"
    os.mkfifo(fifo)
    imports, call = load.split("; ")
    out = refused_in_child(fifo_code(imports, call, str(fifo), "DesignFileError"))
    assert "not a regular file" in out


def test_saving_onto_a_folder_raises_and_leaves_no_temporary_file(tmp_path):
    # issue 31: `softgym convert` into a folder left a .tmp<pid> file behind
    from softgym.design import default_walker
    from softgym.design.vxa import save_vxa
    from softgym.exceptions import DesignFileError

    target = tmp_path / "out"
    target.mkdir()
    with pytest.raises(DesignFileError, match="is a folder"):
        default_walker().save(target)
    with pytest.raises(DesignFileError, match="is a folder"):
        save_vxa(default_walker(), target)
    assert sorted(p.name for p in tmp_path.rglob("*")) == ["out"]


def test_loading_something_that_is_not_a_path_is_a_design_file_error():
    # issue 61: RobotDesign.load(5) was a TypeError from os.fspath
    from softgym.exceptions import DesignFileError

    for bad in (5, None, 1.5, ["a.json"]):
        with pytest.raises(DesignFileError, match="must be a path"):
            RobotDesign.load(bad)

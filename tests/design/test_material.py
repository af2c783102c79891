import json

import pytest

from softgym.design.material import (
    EVOLVABLE_BOUNDS,
    Material,
    MaterialBounds,
    Palette,
    default_palette,
    seed_materials,
)
from softgym.exceptions import InvalidDesignError, InvalidParameterError

# ---------------------------------------------------------------- Material


def test_seed_palette_values():
    p = default_palette()
    assert list(p) == list(range(1, 10))
    assert [p[k].name for k in p] == [
        "Passive_Soft",
        "Passive_Hard",
        "Active_+",
        "Active_-",
        "Obstacle",
        "New_Passive_Soft",
        "New_Passive_Hard",
        "New_Active_+",
        "New_Active_-",
    ]
    assert [p[k].youngs_modulus for k in p] == [5e6, 5e8, 5e6, 5e6, 5e9, 5e6, 5e8, 5e6, 5e6]
    assert [p[k].cte for k in p] == [0, 0, 0.01, -0.01, 0, 0, 0, 0.05, -0.05]
    for m in p.values():
        assert (m.density, m.poisson, m.mu_static, m.mu_kinetic) == (1e6, 0.35, 1.0, 0.5)
    assert p[5].color == (1.0, 0.784, 0.0, 1.0)
    assert p[8].color == (1.0, 1.0, 0.0, 1.0)


def test_seed_materials_is_a_fresh_dict():
    a = seed_materials()
    a[1] = a[2]
    assert seed_materials()[1].name == "Passive_Soft"


@pytest.mark.parametrize(
    "kwargs, needle",
    [
        ({"youngs_modulus": 0.0}, "youngs_modulus must lie in"),
        ({"youngs_modulus": float("nan")}, "youngs_modulus must be finite"),
        ({"density": -1.0}, "density must lie in"),
        ({"poisson": 0.5}, "poisson must lie in [0, 0.5)"),
        ({"poisson": -0.1}, "poisson must lie in [0, 0.5)"),
        ({"mu_static": -1.0}, "friction"),
        ({"cte": float("inf")}, "cte must be finite"),
        ({"color": (1.0, 2.0, 0.0)}, "color"),
        ({"color": (1.0, 0.0)}, "color"),
        ({"youngs_modulus": "soft"}, "must be a number"),
        ({"youngs_modulus": 1e300}, "youngs_modulus must lie in"),
        ({"density": 1e-300}, "density must lie in"),
    ],
)
def test_material_rejects_unphysical_values(kwargs, needle):
    base = {"name": "m", "youngs_modulus": 5e6}
    base.update(kwargs)
    with pytest.raises(InvalidParameterError) as exc:
        Material(**base)
    assert needle in str(exc.value)
    assert "'m'" in str(exc.value)


def test_material_color_gets_alpha_and_dict_roundtrip():
    m = Material("x", 1e7, density=2e3, cte=-0.02, color=(0.1, 0.2, 0.3))
    assert m.color == (0.1, 0.2, 0.3, 1.0)
    assert m.is_active
    again = Material.from_dict(json.loads(json.dumps(m.to_dict())))
    assert again == m
    with pytest.raises(InvalidDesignError, match="unknown material field"):
        Material.from_dict({**m.to_dict(), "stiffness": 3})


def test_material_bounds_clip_and_check():
    b = EVOLVABLE_BOUNDS
    assert b == MaterialBounds((5e6, 5e8), (1e3, 1e7), (0.001, 0.04))
    muscle = Material("m", 1e9, density=10.0, cte=-0.08)
    clipped = b.clip(muscle)
    assert (clipped.youngs_modulus, clipped.density, clipped.cte) == (5e8, 1e3, -0.04)
    tissue = Material("t", 1e6)
    assert b.clip(tissue).cte == 0.0 and b.clip(tissue).youngs_modulus == 5e6
    b.check(clipped)
    with pytest.raises(InvalidParameterError, match="density = 10.0"):
        b.check(muscle.replace(youngs_modulus=5e6))
    with pytest.raises(InvalidParameterError, match=r"\|cte\|"):
        b.check(Material("m", 5e6, cte=0.0001))


# ---------------------------------------------------------------- Palette


def test_palette_is_one_based_mapping():
    soft = Material("soft", 5e6)
    hard = Material("hard", 5e8)
    p = Palette([soft, hard])
    assert p[1] is soft and p[2] is hard and len(p) == 2 and p.max_id == 2
    assert 0 not in p
    with pytest.raises(KeyError, match="no material with id 3"):
        p[3]
    q = Palette({7: hard, 2: soft})
    assert list(q) == [2, 7] and q.max_id == 7
    assert p == Palette({1: soft, 2: hard})
    assert p != q


@pytest.mark.parametrize(
    "bad", [{0: Material("a", 1.0)}, {128: Material("a", 1.0)}, {1: "steel"}, {}]
)
def test_palette_rejects_bad_entries(bad):
    with pytest.raises(InvalidDesignError):
        Palette(bad)


def test_palette_counterphase_copies_material_8_into_9():
    p = default_palette().with_changes(8, youngs_modulus=7e6, density=5e5, cte=0.031)
    q = p.with_counterphase(8, 9)
    assert q[9].name == "New_Active_-"
    assert (q[9].youngs_modulus, q[9].density, q[9].cte) == (7e6, 5e5, -0.031)
    assert q[8] == p[8]
    # adding a target that does not exist yet
    r = Palette({1: p[8]}).with_counterphase(1, 2)
    assert r[2].cte == -0.031


def test_palette_list_roundtrip_and_errors():
    p = default_palette()
    assert Palette.from_list(json.loads(json.dumps(p.to_list()))) == p
    items = p.to_list()
    with pytest.raises(InvalidDesignError, match="twice"):
        Palette.from_list(items + [items[0]])
    with pytest.raises(InvalidDesignError, match="no 'id'"):
        Palette.from_list([{"name": "a", "youngs_modulus": 1.0}])
    with pytest.raises(InvalidDesignError, match="id 1: .*poisson"):
        Palette.from_list([{"id": 1, "name": "a", "youngs_modulus": 1.0, "poisson": 0.7}])

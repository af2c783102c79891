"""Hostile inputs to Material, Palette, Controller and CompositionRules: valid or a SoftGymError."""

import math

import numpy as np
import pytest
from fuzzing import FUZZ, outcome  # tests/fuzzing.py
from hypothesis import given
from hypothesis import strategies as st

from softgym.design import (
    MAX_ABS_CTE,
    CompositionRules,
    Controller,
    Material,
    Palette,
    default_walker,
)
from softgym.exceptions import InvalidDesignError, InvalidParameterError

# ------------------------------------------------------------------ reproducers of issue 12


@pytest.mark.parametrize(
    "kwargs, needle",
    [
        ({"cte": 10}, f"cte must lie in [-{MAX_ABS_CTE}, {MAX_ABS_CTE}]"),
        ({"cte": -0.2}, "cte must lie in"),
        ({"youngs_modulus": True}, "youngs_modulus must be a number, got True"),
        ({"density": "1e6"}, "density must be a number"),
        ({"poisson": 1j}, "poisson must be a number"),
        ({"color": "abc"}, "color must be a sequence"),
        ({"color": 5}, "color must be a sequence"),
        ({"color": (1, 0, True)}, "color channel must be a number"),
        ({"mu_static": [1.0]}, "mu_static must be a number"),
        ({"youngs_modulus": 10**400}, "youngs_modulus must be a finite number"),
    ],
)
def test_material_refuses_nonsense(kwargs, needle):
    with pytest.raises(InvalidParameterError) as exc:
        Material(**{"name": "m", "youngs_modulus": 5e6, **kwargs})
    assert needle in str(exc.value)


def test_material_accepts_numpy_scalars_and_the_seed_extremes():
    m = Material("m", np.float32(5e6), density=np.int64(1000), cte=-0.05, color=np.ones(3))
    assert m.youngs_modulus == 5e6 and type(m.density) is float and m.color == (1, 1, 1, 1)
    assert Material("m", 5e6, cte=MAX_ABS_CTE).cte == MAX_ABS_CTE


@pytest.mark.parametrize("key", [[1], (1,), 1.0, True, "1", None, 0, 128, -1])
def test_palette_ids_must_be_ints_in_range(key):
    entry = {"id": key, **Material("m", 5e6).to_dict()}
    with pytest.raises(InvalidDesignError, match="'id' must be an integer in 1..127"):
        Palette.from_list([entry])


def test_palette_constructor_and_lookup_are_typed():
    assert Palette({np.int8(3): Material("m", 5e6)}).max_id == 3
    with pytest.raises(InvalidDesignError, match="a palette takes"):
        Palette(Material("m", 5e6))
    with pytest.raises(KeyError):
        default_walker().palette[[1]]
    assert [1] not in default_walker().palette


@pytest.mark.parametrize(
    "kwargs, needle",
    [
        ({"period": True}, "controller period must be a number, got True"),
        ({"period": "0.25"}, "controller period must be a number"),
        ({"temp_amplitude": [14]}, "must be a number"),
    ],
)
def test_controller_refuses_bools_and_strings(kwargs, needle):
    with pytest.raises(InvalidParameterError, match=needle):
        Controller(**kwargs)
    with pytest.raises(InvalidParameterError, match=needle):
        Controller.clipped(**kwargs)


@pytest.mark.parametrize(
    "kwargs, needle",
    [
        ({"min_filled_fraction": 1.5}, "must lie in [0, 1]"),
        ({"min_filled_fraction": "0.3"}, "must be a number in [0, 1]"),
        ({"min_bone_voxels": 1.5}, "min_bone_voxels must be an integer"),
        ({"require_connected": "yes"}, "require_connected must be a bool"),
        ({"muscle_ids": (3, 300)}, "material ids in 1..127"),
        ({"muscle_ids": "34"}, "sequence of material ids"),
    ],
)
def test_composition_rules_are_validated(kwargs, needle):
    with pytest.raises(InvalidParameterError) as exc:
        CompositionRules(**kwargs)
    assert needle in str(exc.value)
    with pytest.raises(InvalidParameterError, match="unknown composition rule"):
        CompositionRules.from_dict({"min_filled": 0.3})
    assert CompositionRules.from_dict(CompositionRules.seed().to_dict()) == CompositionRules.seed()


# ------------------------------------------------------------------ properties

SCALARS = (
    st.none()
    | st.booleans()
    | st.integers(min_value=-(2**70), max_value=2**70)
    | st.floats(allow_nan=True, allow_infinity=True)
    | st.floats(-1, 1)
    | st.floats(0, 1e10)
    # physical extremes (issue 31): time steps that round to 0, buffers that overflow
    | st.sampled_from([1e-300, 1e300, -1e300, 5e-324, 1e-30, 1e30])
    | st.floats(1e-300, 1e300)
    | st.text(max_size=6)
    | st.complex_numbers(max_magnitude=10)
    | st.lists(st.floats(-1, 2), max_size=5)
)
MATERIAL_FIELDS = [
    "youngs_modulus",
    "density",
    "poisson",
    "cte",
    "mu_static",
    "mu_kinetic",
    "color",
]


@FUZZ
@given(st.dictionaries(st.sampled_from(MATERIAL_FIELDS), SCALARS, max_size=4))
def test_materials_are_valid_or_refused(changes):
    label = outcome(
        "material: Material(**fields)", Material, "m", **{"youngs_modulus": 5e6, **changes}
    )
    if label == "valid":
        m = Material("m", **{"youngs_modulus": 5e6, **changes})
        values = [m.youngs_modulus, m.density, m.poisson, m.cte, m.mu_static, m.mu_kinetic]
        assert all(type(v) is float and math.isfinite(v) for v in values)
        assert abs(m.cte) <= MAX_ABS_CTE and m.youngs_modulus > 0 and m.density > 0
        assert Material.from_dict(m.to_dict()) == m
        # an accepted material gives a robot a usable time step
        from softgym.design import Palette, RobotDesign
        from softgym.engine import time_step

        design = RobotDesign(np.ones((2, 1, 1), dtype=int), palette=Palette({1: m}))
        dt = time_step(design)
        assert math.isfinite(dt) and dt > 0


@FUZZ
@given(
    st.lists(
        st.dictionaries(st.sampled_from(["id", "name", *MATERIAL_FIELDS]), SCALARS, max_size=8),
        max_size=4,
    )
    | SCALARS
)
def test_palette_lists_are_valid_or_refused(items):
    outcome("material: Palette.from_list", Palette.from_list, items)


@FUZZ
@given(st.dictionaries(st.sampled_from(["temp_amplitude", "period", "muscle_cte", "x"]), SCALARS))
def test_controllers_are_valid_or_refused(data):
    label = outcome("material: Controller.from_dict", Controller.from_dict, data)
    if label == "valid":
        c = Controller.from_dict(data)
        assert all(type(v) is float for v in c.to_dict().values())
    outcome(
        "material: Controller.clipped",
        Controller.clipped,
        **{k: v for k, v in data.items() if k != "x"},
    )


RULE_FIELDS = [
    "min_filled_fraction",
    "min_muscle_fraction_of_grid",
    "min_bone_voxels",
    "require_connected",
    "muscle_ids",
    "bone_ids",
]


@FUZZ
@given(
    st.dictionaries(
        st.sampled_from(RULE_FIELDS), SCALARS | st.lists(st.integers(-2, 130), max_size=3)
    )
)
def test_composition_rules_are_valid_or_refused(data):
    label = outcome("material: CompositionRules.from_dict", CompositionRules.from_dict, data)
    if label == "valid":
        rules = CompositionRules.from_dict(data)
        outcome("material: rules.violations", default_walker().violations, rules)

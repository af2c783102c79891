import json

import numpy as np

from evolvers.operators.genome import INITIAL_MATERIAL_GENES, Individual
from softgym.design import MATERIAL_TREE_8, CompositionRules, Controller


def test_random_individual_is_valid_and_deterministic():
    a = Individual.random(np.random.default_rng(3), 0, (4, 4, 4))
    b = Individual.random(np.random.default_rng(3), 0, (4, 4, 4))
    assert a.cppn == b.cppn
    assert not CompositionRules.seed().violations(a.grid((4, 4, 4)))
    assert a.phenotype_key((4, 4, 4)) == b.phenotype_key((4, 4, 4))


def test_json_round_trip_keeps_everything():
    ind = Individual.random(np.random.default_rng(1), 7, (4, 4, 4), MATERIAL_TREE_8)
    ind.controller = Controller(10.0, 0.3, 0.02)
    ind.materials[2, 1] = 123456.0
    ind.age, ind.parent_id = 3, 2
    ind.objectives = {"norm_final_dist": 1.5}
    back = Individual.from_dict(json.loads(json.dumps(ind.to_dict())))
    assert back.to_dict() == ind.to_dict()
    assert back.phenotype_key((4, 4, 4)) == ind.phenotype_key((4, 4, 4))


def test_phenotype_key_tracks_controller_and_used_materials_only():
    ind = Individual.random(np.random.default_rng(2), 0, (4, 4, 4))  # 4-output tree: ids 1-4
    key = ind.phenotype_key((4, 4, 4))
    other = ind.child(1)
    other.materials[0, 0] = 6e6  # material 6 is not in the grid
    assert other.phenotype_key((4, 4, 4)) == key
    other.controller = Controller(15.0, 0.25, 0.01)
    assert other.phenotype_key((4, 4, 4)) != key


def test_palette_carries_material_genes():
    ind = Individual.random(np.random.default_rng(0), 0, (4, 4, 4))
    pal = ind.palette()
    np.testing.assert_array_equal(
        [[pal[k].youngs_modulus, pal[k].density, pal[k].cte] for k in (6, 7, 8, 9)],
        INITIAL_MATERIAL_GENES,
    )
    child = ind.child(5)
    assert child.parent_id == ind.id and child.id == 5 and child.age == ind.age
    assert child.objectives == {}

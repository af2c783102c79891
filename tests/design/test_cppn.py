import json

import numpy as np
import pytest

from softgym.design.cppn import (
    ACTIVATIONS,
    CPPN,
    HIDDEN_ACTIVATIONS,
    INPUT_NAMES,
    MATERIAL_TREE_4,
    MATERIAL_TREE_8,
    MUTATIONS,
    cppn_inputs,
    material_tree,
)
from softgym.design.robot import CompositionRules, RobotDesign, label_components
from softgym.exceptions import InvalidDesignError, InvalidParameterError

SEED_RULES = CompositionRules.seed()


def genome(outputs, nodes, edges):
    """A CPPN from explicit hidden/output nodes and links (via the JSON form)."""
    return CPPN.from_dict(
        {
            "schema": "softgym.cppn",
            "version": 1,
            "outputs": list(outputs),
            "nodes": [{"id": o, "kind": "output", "activation": "sigmoid"} for o in outputs]
            + [{"id": n, "kind": k, "activation": a} for n, k, a in nodes],
            "edges": [list(e) for e in edges],
        }
    )


def is_acyclic(g):
    try:
        g._touch()
        g._topological_order()
    except InvalidDesignError:
        return False
    return True


# ---------------------------------------------------------------- inputs & expression


def test_inputs_are_normalised_like_the_seed():
    inp = cppn_inputs((6, 6, 6))
    assert np.allclose(inp["x"][:, 0, 0], [-1, -0.6, -0.2, 0.2, 0.6, 1])
    assert np.allclose(inp["z"][0, 0, :], [-1, -0.6, -0.2, 0.2, 0.6, 1])
    assert (inp["b"] == 1).all()
    d = inp["d"]
    assert d.min() == pytest.approx(-1) and d.max() == pytest.approx(1)
    # corners are farthest, the 8 central voxels nearest
    assert d[0, 0, 0] == d[5, 5, 5] == pytest.approx(1)
    assert d[2, 2, 2] == d[3, 3, 3] == pytest.approx(-1)
    r = np.sqrt(3 * 0.2**2), np.sqrt(3.0)
    expected = 2 * (np.sqrt(0.6**2 + 0.2**2 + 0.2**2) - r[0]) / (r[1] - r[0]) - 1
    assert d[4, 2, 2] == pytest.approx(expected)
    flat = cppn_inputs((3, 1, 2))
    assert (flat["y"] == -1).all()  # a size-1 axis maps to -1, as the seed's normalize
    assert np.allclose(flat["x"][:, 0, 0], [-1, 0, 1])


def test_minimal_genome_draws_nothing():
    g = CPPN()
    assert g.nodes == list(INPUT_NAMES) + list(MATERIAL_TREE_4)
    assert len(g.edges) == 20 and set(g.edges.values()) == {0.0}
    out = g.evaluate((6, 6, 6))
    assert all((v == 0).all() for v in out.values())  # sigmoid(0) = 0
    assert not g.to_grid().any()


def test_four_output_tree_by_hand():
    # shape everywhere; muscle where x > 0; Active_+ where y > 0; soft tissue where z > 0
    g = genome(
        MATERIAL_TREE_4,
        [],
        [
            ("b", "shape", 1.0),
            ("x", "muscleOrTissue", 1.0),
            ("y", "muscleType", 1.0),
            ("z", "tissueType", 1.0),
        ],
    )
    grid = g.to_grid((4, 4, 4))
    x, y, z = np.meshgrid(*(np.arange(4),) * 3, indexing="ij")
    expected = np.where(x >= 2, np.where(y >= 2, 3, 4), np.where(z >= 2, 1, 2))
    assert np.array_equal(grid, expected)
    d = g.to_design((4, 4, 4))
    assert isinstance(d, RobotDesign) and d.n_voxels == 64


def test_eight_output_tree_by_hand():
    g = genome(
        MATERIAL_TREE_8,
        [],
        [
            ("b", "shape", 1.0),
            ("x", "newOrOld", 1.0),
            ("y", "newMuscleOrTissue", 1.0),
            ("y", "oldMuscleOrTissue", -1.0),
            ("z", "newMuscleType", 1.0),
            ("z", "newTissueType", -1.0),
            ("z", "muscleType", -1.0),
            ("z", "tissueType", 1.0),
        ],
    )
    grid = g.to_grid((2, 2, 2))
    # x=1 -> new branch: y=1 muscle (z=1 -> 8, z=0 -> 9); y=0 tissue (z=0 -> 6, z=1 -> 7)
    # x=0 -> old branch: y=0 muscle (z=0 -> 3, z=1 -> 4); y=1 tissue (z=1 -> 1, z=0 -> 2)
    assert grid[1, 1, 1] == 8 and grid[1, 1, 0] == 9 and grid[1, 0, 0] == 6 and grid[1, 0, 1] == 7
    assert grid[0, 0, 0] == 3 and grid[0, 0, 1] == 4 and grid[0, 1, 1] == 1 and grid[0, 1, 0] == 2


def test_material_tree_keeps_largest_body():
    shape = -np.ones((5, 1, 1))
    shape[[0, 2, 3], 0, 0] = 1
    outputs = {
        "shape": shape,
        "muscleOrTissue": np.ones_like(shape),
        "muscleType": np.ones_like(shape),
        "tissueType": np.ones_like(shape),
    }
    assert material_tree(outputs)[:, 0, 0].tolist() == [0, 0, 3, 3, 0]
    assert material_tree(outputs, keep_largest=False)[:, 0, 0].tolist() == [3, 0, 3, 3, 0]
    with pytest.raises(InvalidDesignError, match="match no material tree"):
        material_tree({"shape": shape})


def test_every_consumer_sees_the_activated_hidden_value():
    # hidden node h = abs(x) feeds two outputs; the seed's cache would hand the second one x, not |x|
    g = genome(
        MATERIAL_TREE_4,
        [(0, "hidden", "abs")],
        [("x", 0, 1.0), (0, "shape", 1.0), (0, "muscleOrTissue", 1.0)],
    )
    out = g.evaluate((6, 6, 6))
    ax = np.abs(cppn_inputs()["x"])
    expected = 2 / (1 + np.exp(-ax)) - 1
    assert np.allclose(out["shape"], expected)
    assert np.allclose(out["muscleOrTissue"], expected)


def test_activation_set():
    x = np.array([-4.0, -0.25, 0.0, 2.0])
    assert HIDDEN_ACTIVATIONS == (
        "sin",
        "abs",
        "neg_abs",
        "square",
        "neg_square",
        "sqrt_abs",
        "neg_sqrt_abs",
    )
    assert np.allclose(ACTIVATIONS["neg_sqrt_abs"](x), [-2.0, -0.5, 0.0, -np.sqrt(2)])
    assert np.allclose(ACTIVATIONS["neg_square"](x), [-16.0, -0.0625, 0.0, -4.0])
    assert np.allclose(ACTIVATIONS["sigmoid"](np.array([0.0, np.log(3)])), [0.0, 0.5])


# ---------------------------------------------------------------- random genomes & mutation


def test_random_genome_is_deterministic_and_follows_the_seed_recipe():
    a = CPPN.random(rng=11)
    assert a == CPPN.random(rng=np.random.default_rng(11))
    assert a != CPPN.random(rng=12)
    assert is_acyclic(a)
    assert len(a.hidden) <= 5
    # pruned: every hidden node has an incoming and an outgoing link
    for h in a.hidden:
        assert any(b == h for _, b in a.edges) and any(s == h for s, _ in a.edges)
    assert all(-1.0 <= w <= 1.0 for w in a.edges.values())


def test_random_valid_and_eight_outputs():
    g = CPPN.random_valid(MATERIAL_TREE_8, rng=5, is_valid=SEED_RULES)
    grid = g.to_grid()
    assert RobotDesign(grid).is_valid(SEED_RULES)
    assert set(np.unique(grid)) <= {0, 1, 2, 3, 4, 6, 7, 8, 9}
    with pytest.raises(InvalidDesignError, match="no valid random CPPN"):
        CPPN.random_valid(rng=0, is_valid=lambda grid: False, max_attempts=3)


def test_mutation_is_deterministic():
    parent = CPPN.random_valid(rng=21, is_valid=SEED_RULES)
    a = parent.mutate(rng=7, is_valid=SEED_RULES)
    b = parent.mutate(rng=np.random.default_rng(7), is_valid=SEED_RULES)
    assert a.genome == b.genome and a.operator == b.operator and a.attempts == b.attempts
    # the genome survives JSON with its node and link order, so mutation stays reproducible
    again = CPPN.from_json(parent.to_json())
    c = again.mutate(rng=7, is_valid=SEED_RULES)
    assert c.genome == a.genome


@pytest.mark.parametrize("seed", range(6))
def test_mutation_gives_a_valid_changed_phenotype(seed):
    parent = CPPN.random_valid(rng=100 + seed, is_valid=SEED_RULES)
    before = parent.to_json()
    res = parent.mutate(rng=seed, is_valid=SEED_RULES)
    assert res.success and res.operator in MUTATIONS and 1 <= res.attempts <= 1500
    child_grid = res.genome.to_grid()
    assert not np.array_equal(child_grid, parent.to_grid())
    RobotDesign(child_grid).validate(SEED_RULES)
    assert len(label_components(child_grid != 0)[1]) == 1
    assert is_acyclic(res.genome)
    assert parent.to_json() == before  # the parent is untouched


def test_mutation_gives_up_after_max_attempts():
    parent = CPPN.random_valid(rng=1, is_valid=SEED_RULES)
    res = parent.mutate(rng=0, is_valid=lambda grid: False, max_attempts=25)
    assert not res.success and res.operator is None and res.attempts == 25
    assert res.genome == parent and res.genome is not parent
    with pytest.raises(InvalidParameterError):
        parent.mutate(rng=0, max_attempts=0)


def test_operators_one_by_one():
    rng = np.random.default_rng(0)
    g = CPPN.random(rng=2)
    n_edges, n_hidden = len(g.edges), len(g.hidden)

    h = g.apply_mutation("add_node", rng)
    assert len(h.hidden) == n_hidden + 1 and len(h.edges) == n_edges + 1
    new = max(h.hidden)
    (src, w_in), (dst, w_out) = (
        [(a, w) for (a, b), w in h.edges.items() if b == new][0],
        [(b, w) for (a, b), w in h.edges.items() if a == new][0],
    )
    assert (src, dst) in g.edges and (src, dst) not in h.edges
    assert w_in == g.edges[(src, dst)] and w_out == 1.0
    assert h.activation(new) in HIDDEN_ACTIVATIONS

    h = g.apply_mutation("remove_link", rng)
    assert len(h.edges) <= n_edges - 1

    h = g.apply_mutation("add_link", rng)
    added = set(h.edges) - set(g.edges)
    assert len(added) == 1 and abs(h.edges[added.pop()]) == 0.1
    assert is_acyclic(h)

    h = g.apply_mutation("mutate_weight", rng)
    changed = [e for e in g.edges if g.edges[e] != h.edges[e]]
    assert len(changed) == 1 and -1.0 <= h.edges[changed[0]] <= 1.0

    h = g.apply_mutation("mutate_function", rng)
    changed = [n for n in g.nodes if g.activation(n) != h.activation(n)]
    assert len(changed) == 1 and changed[0] not in INPUT_NAMES
    assert h.activation(changed[0]) in HIDDEN_ACTIVATIONS

    with pytest.raises(InvalidParameterError, match="unknown mutation"):
        g.apply_mutation("crossover", rng)


def test_remove_node_bridges_with_product_weights():
    g = genome(
        MATERIAL_TREE_4,
        [(0, "hidden", "sin")],
        [("x", 0, 0.5), ("y", 0, -0.4), (0, "shape", 0.8)],
    )
    h = g.apply_mutation("remove_node", 0)
    assert h.hidden == []
    assert h.edges[("x", "shape")] == pytest.approx(0.4)
    assert h.edges[("y", "shape")] == pytest.approx(-0.32)


def test_add_link_never_closes_a_cycle():
    g = CPPN.random(rng=4)
    for seed in range(30):
        g = g.apply_mutation("add_link", seed)
        assert is_acyclic(g)
    for a, b in g.edges:
        assert a not in MATERIAL_TREE_4 and b not in INPUT_NAMES


# ---------------------------------------------------------------- JSON


def test_json_roundtrip_and_errors():
    g = CPPN.random(MATERIAL_TREE_8, rng=9)
    text = g.to_json()
    assert "pickle" not in text
    h = CPPN.from_json(text)
    assert h == g
    assert np.array_equal(h.to_grid(), g.to_grid())
    data = json.loads(text)
    with pytest.raises(InvalidDesignError, match="newer than this softgym"):
        CPPN.from_dict({**data, "version": 99})
    with pytest.raises(InvalidDesignError, match="schema"):
        CPPN.from_dict({**data, "schema": "x"})
    with pytest.raises(InvalidDesignError, match="unknown activation 'relu'"):
        genome(MATERIAL_TREE_4, [(0, "hidden", "relu")], [])
    with pytest.raises(InvalidDesignError, match="goes into an input"):
        genome(MATERIAL_TREE_4, [], [("shape", "x", 1.0)])
    with pytest.raises(InvalidDesignError, match="unknown node"):
        genome(MATERIAL_TREE_4, [], [("x", 7, 1.0)])
    with pytest.raises(InvalidDesignError, match="cycle"):
        genome(
            MATERIAL_TREE_4,
            [(0, "hidden", "sin"), (1, "hidden", "sin")],
            [("x", 0, 1.0), (0, 1, 1.0), (1, 0, 1.0), (1, "shape", 1.0)],
        )
    with pytest.raises(InvalidDesignError, match="not valid JSON"):
        CPPN.from_json("[1, 2")


def test_default_validity_is_the_seed_rules():
    g = CPPN.random_valid(rng=8)
    assert RobotDesign(g.to_grid()).is_valid(SEED_RULES)
    child = g.mutate(rng=8).genome
    assert RobotDesign(child.to_grid()).is_valid(SEED_RULES)
    # CompositionRules() only asks for a non-empty (connected) body
    small = CPPN.random_valid(rng=8, is_valid=CompositionRules(), max_attempts=50)
    assert small.to_grid().any()

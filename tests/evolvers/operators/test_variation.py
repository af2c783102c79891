import numpy as np

from evolvers.operators.genome import Individual
from evolvers.operators.variation import cx_arithmetic, make_children, mut_controller, mut_materials
from softgym.design import CONTROLLER_BOUNDS, CompositionRules, Controller

SHAPE = (4, 4, 4)


def _pop(n, seed=0):
    rng = np.random.default_rng(seed)
    return [Individual.random(rng, i, SHAPE) for i in range(n)]


def test_arithmetic_crossover_touches_floor_rate_pop_children():
    parents = _pop(15)
    for i, p in enumerate(parents):
        p.controller = Controller(1.0 + i, 0.25, 0.01)
    children = [p.child(100 + i) for i, p in enumerate(parents)]
    before = {c.id: c.controller for c in children}
    cx_arithmetic(children, parents, np.random.default_rng(1), rate=0.4)
    changed = [c for c in children if c.controller != before[c.id]]
    assert len(changed) <= 6  # floor(0.4 * 15)
    amps = {1.0 + i for i in range(15)}
    for c in children[:6]:  # the shuffled first six get a mean of two distinct parents
        mean2 = {(a + b) / 2 for a in amps for b in amps if a != b}
        assert c.controller.temp_amplitude in mean2


def test_gaussian_mutation_stays_in_bounds():
    rng = np.random.default_rng(0)
    ind = _pop(1)[0]
    for _ in range(300):
        mut_controller(ind, rng)
        mut_materials(ind, rng)
        for name, (lo, hi, _) in CONTROLLER_BOUNDS.items():
            assert lo <= getattr(ind.controller, name) <= hi
        m = ind.materials
        assert (1e3 <= m[:3, 1]).all() and (m[:3, 1] <= 1e7).all()
        assert 5e6 <= m[0, 0] <= 5e8 and 5e6 <= m[1, 0] <= 5e8
        assert 0.001 <= m[2, 2] <= 0.04
        np.testing.assert_array_equal(m[3], [m[2, 0], m[2, 1], -m[2, 2]])  # 9 = counter-phase of 8
    assert ind.materials[2, 0] == 5e6  # muscle modulus is never mutated


def test_make_children_is_seeded_and_keeps_lineage():
    def run(seed):
        parents = _pop(5)
        for p in parents:
            p.age = 2
        ids = iter(range(100, 200))
        kids = make_children(
            parents,
            np.random.default_rng(seed),
            lambda: next(ids),
            shape=SHAPE,
            evolve_controller=True,
            evolve_materials=True,
        )
        return parents, kids

    parents, kids = run(4)
    _, kids2 = run(4)
    assert [k.to_dict() for k in kids] == [k.to_dict() for k in kids2]
    assert sorted(k.parent_id for k in kids) == [p.id for p in parents]
    assert len({k.id for k in kids}) == 5 and all(k.age == 2 for k in kids)
    rules = CompositionRules.seed()
    for k in kids:
        parent = parents[k.parent_id]
        assert not rules.violations(k.grid(SHAPE))
        assert not np.array_equal(k.grid(SHAPE), parent.grid(SHAPE))  # the body changed

import numpy as np

from evolvers.operators.genome import Individual
from evolvers.operators.selection import (
    Objective,
    pareto_levels,
    sel_fitness_tournament,
    sel_novelty,
    sel_nsga2,
    sel_pareto,
)
from softgym.design import CPPN
from softgym.metrics import WORST_FITNESS

FIT, ENERGY, AGE = Objective("fit", True), Objective("energy", False), Objective("age", False)


def _ind(i, fit, energy=0.0, age=0):
    return Individual(cppn=CPPN(), id=i, age=age, objectives={"fit": fit, "energy": energy})


def test_pareto_levels_count_dominators_and_newer_wins_ties():
    pop = [
        _ind(0, 1.0, 5),
        _ind(1, 2.0, 5),
        _ind(2, 2.0, 5),
        _ind(3, 0.5, 1),
        _ind(4, WORST_FITNESS, 0),
    ]
    lv = pareto_levels(pop, [FIT, ENERGY])
    # 0 is dominated by 1 and 2; the tie 1/2 goes to the newer id 2; 3 is on the front
    assert lv[2] == 0 and lv[3] == 0
    assert lv[1] == 1 and lv[0] == 2
    assert lv[4] >= 2 * len(pop)  # worst fitness gets the seed's extra penalty


def test_sel_pareto_keeps_the_front_and_k():
    pop = [_ind(i, float(i % 7), float(i % 3), age=i % 4) for i in range(31)]
    chosen = sel_pareto(pop, 15, [FIT, ENERGY, AGE], np.random.default_rng(0))
    assert len(chosen) == 15 and len({c.id for c in chosen}) == 15
    lv = pareto_levels(pop, [FIT, ENERGY, AGE])
    front = {pop[i].id for i in np.flatnonzero(lv == 0)}
    assert front <= {c.id for c in chosen} or len(front) > 15
    again = sel_pareto(pop, 15, [FIT, ENERGY, AGE], np.random.default_rng(0))
    assert [c.id for c in again] == [c.id for c in chosen]


def test_fitness_tournament_never_drops_the_best():
    pop = [_ind(i, float(i)) for i in range(31)]
    chosen = sel_fitness_tournament(pop, 15, "fit", np.random.default_rng(1))
    assert len(chosen) == 15 and 30 in {c.id for c in chosen}
    assert 0 not in {c.id for c in chosen}  # the worst loses every tournament it enters


def test_novelty_seed_keeps_most_different_and_nsga2_runs():
    t = np.linspace(1.0, 4.5, 8)
    pop = []
    for i in range(6):
        ind = _ind(i, 0.0)
        x = (t - 1) * 0.05 * (1 + 0.01 * i)  # five robots walk straight, one zig-zags
        y = np.zeros_like(t) if i < 5 else 0.03 * (np.arange(t.size) % 2)
        ind.trace = np.column_stack([x, y, np.full_like(t, 0.02), t])
        pop.append(ind)
    chosen = sel_novelty(pop, 1, time_scale=0.0)
    assert chosen[0].id == 5 and all(p.novelty is not None for p in pop)
    pop2 = [_ind(i, float(i % 5), float(i % 3)) for i in range(10)]
    assert len(sel_nsga2(pop2, 4, [FIT, ENERGY])) == 4

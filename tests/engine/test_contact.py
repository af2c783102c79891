"""Contact with terrain boxes and self-collision (tolerances stated per test).

Terrain boxes: the corotational model's penalty contact with friction (box
tests below pin it); the seed model turns lattice boxes into the seed's fixed
obstacle voxels (tests at the end).
"""

import numpy as np
import pytest
from engine_builders import kinetic_acceleration, reference_robot, settled_block, static_slip

from softgym.engine import Body, SimConfig, Simulation
from softgym.terrain import Box, Terrain

L = 0.01
BOXES = SimConfig.corotational(init_time=0.0)  # the penalty box contact


def test_block_dropped_onto_a_box_rests_on_its_top_within_2_percent():
    # A 2x2x1 block dropped from 2 voxels above a 2-voxel-high platform comes to
    # rest with its centres at top + L/2 (within 2 %).
    platform = Terrain.from_boxes([Box((-4, -4, 0), (6, 6, 2))])
    body = Body.uniform(np.ones((2, 2, 1)), origin=(0.0, 0.0, 4 * L))
    sim = Simulation(body, BOXES, terrain=platform)
    sim.advance(1.5)
    z = sim.positions(0)[:, 2]
    assert np.abs(sim.velocities(0)).max() < 1e-4
    np.testing.assert_allclose(z, 2 * L + 0.5 * L, rtol=0.02)


def test_robot_driven_into_a_wall_never_enters_it():
    # The seed's 1-voxel fence; a flat 2x2x1 block (at the benchmark's dt)
    # pushed towards the east wall with 0.8 times its weight (kinetic friction
    # takes 0.5): no voxel centre is ever inside a wall box, and the block
    # stops at the wall.
    fence = Terrain.fence(inner=10, height=1, thickness=1, center=(1.0, 1.0))
    walls = fence.as_array(L)
    body = Body.uniform(np.ones((2, 2, 1)))
    sim = Simulation(body, BOXES, terrain=fence)
    m = sim.masses(0)[0]
    sim.set_external_force(0, [0.8 * 9.81 * m, 0.0, 0.0])
    dt = sim.dt[0]
    x_late = None
    for step in range(int(2.0 / dt)):
        sim.advance(dt)
        if step == int(1.8 / dt):
            x_late = sim.positions(0)[:, 0].copy()
        p = sim.positions(0)
        inside = (
            (p[:, None, 0] > walls[None, :, 0]) & (p[:, None, 0] < walls[None, :, 3])
            & (p[:, None, 1] > walls[None, :, 1]) & (p[:, None, 1] < walls[None, :, 4])
            & (p[:, None, 2] > walls[None, :, 2]) & (p[:, None, 2] < walls[None, :, 5])
        )  # fmt: skip
        assert not inside.any(), f"a voxel centre entered a wall at t = {sim.time[0]:.4f} s"
    east_wall_x = 1.0 * L + 5 * L  # centre + inner / 2
    assert sim.positions(0)[:, 0].max() < east_wall_x
    assert sim.positions(0)[:, 0].max() > east_wall_x - L  # it got there
    assert np.abs(sim.positions(0)[:, 0] - x_late).max() < 1e-4  # and stays there


def _block_on_platform(mu_s, mu_k):
    platform = Terrain.from_boxes([Box((-20, -20, 0), (40, 40, 2))])
    return settled_block(mu_s, mu_k, terrain=platform, z0=2 * L, model="corotational")


def test_static_friction_on_a_box_top_matches_the_floor():
    # F = 0.9 mu_s N: no sliding (< 1e-6 m in 1 s), as on the floor.
    assert static_slip(_block_on_platform(1.0, 0.5)) < 1e-6


def test_kinetic_friction_on_a_box_top_matches_the_floor():
    # F = 1.5 mu_s N: a = (F - mu_k N) / m within 2 %, as on the floor.
    mu_s, mu_k = 1.0, 0.5
    sim = _block_on_platform(mu_s, mu_k)
    m = sim.masses(0)[0]
    N = m * 9.81
    F = 1.5 * mu_s * N
    assert kinetic_acceleration(sim, F) == pytest.approx((F - mu_k * N) / m, rel=0.02)


def _c_shape_pulled_shut(self_collision):
    # A flat C (base along y, two arms along x), tips pulled towards each other.
    g = np.zeros((6, 5, 1), dtype=np.int32)
    g[0, :, 0] = 1
    g[:, 0, 0] = 1
    g[:, 4, 0] = 1
    body = Body.uniform(g, youngs_modulus=5e5)
    cfg = SimConfig(self_collision=self_collision, init_time=0.0, gravity=0.0, floor=False,
                    global_damping=0.05)  # fmt: skip
    sim = Simulation(body, cfg)
    _pull_shut(sim, 0)
    return sim


def _pull_shut(sim, robot):
    # the C's tips pulled towards each other
    idx = sim.grid_index(robot)
    f = np.zeros((len(idx), 3))
    f[(idx[:, 0] == 5) & (idx[:, 1] == 0), 1] = 2.0
    f[(idx[:, 0] == 5) & (idx[:, 1] == 4), 1] = -2.0
    sim.set_external_force(robot, f)


def _min_distance_of_colliding_pairs(sim, seconds, hops=3):
    # smallest centre distance over pairs more than `hops` bonds apart, in L
    from softgym.engine.layout import _hop_neighbours

    off = sim.voxel_offsets
    a = sim._a
    v1 = a["v1"] - off[0]
    v2 = a["v2"] - off[0]
    n = off[1] - off[0]
    start, index = _hop_neighbours(n, v1, v2, hops)
    near = np.eye(n, dtype=bool)
    for i in range(n):
        near[i, index[start[i] : start[i + 1]]] = True
    smallest = np.inf
    for _ in range(int(seconds / 0.02)):
        sim.advance(0.02)
        p = sim.positions(0)
        d = np.linalg.norm(p[:, None] - p[None], axis=-1)
        smallest = min(smallest, d[~near].min())
    return smallest / L


def test_self_collision_prevents_interpenetration_of_a_folded_body():
    # With self-collision the arms stop at the contact law's envelope (1.5 L,
    # less the penalty overlap): never closer than 1 L. Without it they pass
    # through each other (the test really folds the body).
    assert _min_distance_of_colliding_pairs(_c_shape_pulled_shut(True), 3.0) > 1.0
    assert _min_distance_of_colliding_pairs(_c_shape_pulled_shut(False), 3.0) < 0.5


def _contact_batch():
    fence = Terrain.fence(center=(1.5, 1.5), inner=8)
    pulled = _c_shape_pulled_shut(True).bodies[0]
    return [reference_robot(3), pulled, reference_robot(4, cte=0.03)], [fence, Terrain.flat(), fence]


def test_contact_results_bit_identical_alone_batched_and_threaded():
    bodies, terrains = _contact_batch()
    cfg = SimConfig(actuation="symmetric")
    finals = []
    for n_threads in (1, 2):
        sim = Simulation(bodies, cfg, n_threads=n_threads, terrain=terrains)
        rollout = sim.run(1.6)
        finals.append(rollout.positions)
    assert np.array_equal(finals[0], finals[1])
    for r, (body, terrain) in enumerate(zip(bodies, terrains)):
        alone = Simulation([body], cfg, terrain=terrain).run(1.6)
        assert np.array_equal(alone.robot_positions(0), Simulation(bodies, cfg, terrain=terrains).run(1.6).robot_positions(r))


def test_split_runs_equal_one_run_with_contacts():
    # candidate lists are rebuilt at each call: results must not depend on it
    bodies, terrains = _contact_batch()
    one = Simulation(bodies, terrain=terrains).run(1.5)
    sim = Simulation(bodies, terrain=terrains)
    for _ in range(15):
        sim.advance(0.1)
    assert np.array_equal(one.positions, sim.rollout().positions)


def test_obstacles_are_not_robot_mass():
    # the centre of mass uses the robot's voxels only (the seed counted walls)
    body = Body.uniform(np.ones((2, 2, 2)))
    flat = Simulation(body).rollout()
    fenced = Simulation(body, terrain=Terrain.fence(center=(1, 1))).rollout()
    np.testing.assert_array_equal(flat.cm, fenced.cm)
    assert fenced.mass[0] == pytest.approx(8.0)


def test_voxel_inside_a_box_is_pushed_out_through_the_nearest_face():
    # A voxel whose centre ended 0.3 L inside a box's -x face leaves through it.
    box = Terrain.from_boxes([Box((2, -1, 0), (6, 3, 3))])
    sim = Simulation(Body.uniform(np.ones((1, 1, 1))), BOXES, terrain=box)
    state = sim.get_state()
    state["pos"][0] = [2.3 * L, 0.5 * L, 1.5 * L]
    sim.set_state(state)
    sim.advance(0.05)
    p = sim.positions(0)[0]
    assert p[0] < 2 * L - 0.4 * L  # out through x0, not through the far faces
    assert abs(p[1] - 0.5 * L) < 1e-9


def test_seed_model_walls_are_the_seeds_fixed_voxels():
    # The seed model: a lattice box is the seed's fixed obstacle voxels (E 5e9),
    # touched through the self-collision law (envelopes 0.75 (s1 + s2), no
    # damping, no friction): a block dropped on a 2-voxel platform bounces on
    # it, its centres on average one voxel above its top (the envelope is 1.5 L
    # from the top layer's centres; within 2 %) and never lower than 0.8 L.
    platform = Terrain.from_boxes([Box((-4, -4, 0), (6, 6, 2))])
    body = Body.uniform(np.ones((2, 2, 1)), origin=(0.0, 0.0, 4 * L))
    sim = Simulation(body, SimConfig(init_time=0.0, trace_interval=0.01), terrain=platform)
    z = []
    for _ in range(150):
        sim.advance(0.01)
        z.append(sim.positions(0)[:, 2].copy())
    z = np.array(z)[50:]
    assert z.min() > 2 * L + 0.8 * L
    assert z.mean() == pytest.approx(2 * L + L, rel=0.02)
    # without self-collision the seed's walls do not exist for the robot
    sim = Simulation(body, SimConfig(init_time=0.0, self_collision=False), terrain=platform)
    sim.advance(0.5)
    assert sim.positions(0)[:, 2].max() < 0.6 * L  # fell through to the floor


def test_seed_model_fence_stops_a_pushed_block():
    # the seed's fence (1-voxel walls, obstacle voxels): a block pushed east with
    # 0.8 of its weight stops against the wall, 1.5 L (the envelopes) short of
    # the wall voxels' centres, and stays there
    fence = Terrain.fence(inner=10, height=1, thickness=1, center=(1.0, 1.0))
    sim = Simulation(Body.uniform(np.ones((2, 2, 1))), SimConfig(init_time=0.0), terrain=fence)
    sim.set_external_force(0, [0.8 * 9.81 * sim.masses(0)[0], 0.0, 0.0])
    sim.advance(1.8)
    x_late = sim.positions(0)[:, 0].max()
    sim.advance(0.2)
    wall_centre = (1.0 + 5.0 + 0.5) * L
    assert wall_centre - 1.7 * L < sim.positions(0)[:, 0].max() < wall_centre - 1.4 * L
    assert abs(sim.positions(0)[:, 0].max() - x_late) < 1e-4


def test_off_lattice_boxes_keep_the_penalty_contact_in_the_seed_model():
    platform = Terrain.from_boxes([Box((-4.5, -4, 0), (6, 6, 2.5))])
    body = Body.uniform(np.ones((2, 2, 1)), origin=(0.0, 0.0, 4 * L))
    sim = Simulation(body, SimConfig(init_time=0.0), terrain=platform)
    sim.advance(1.5)
    np.testing.assert_allclose(sim.positions(0)[:, 2], 2.5 * L + 0.5 * L, rtol=0.02)



def _seed_rule_pairs(sim, robot):
    # the seed's candidate rule by brute force on the robot's col_ref: surface
    # voxels i < j, not excluded, closer than 3 L and than twice the size of
    # the pair's first voxel in the seed's order (robot-local indices)
    a = sim._a
    lo, hi = int(a["vox_start"][robot]), int(a["vox_start"][robot + 1])
    ref, rank, surface = a["col_ref"], a["seed_rank"], a["surface"]
    out = []
    for i in range(lo, hi):
        excluded = set(a["excl_idx"][a["excl_start"][i] : a["excl_start"][i + 1]])
        for j in range(i + 1, hi):
            if not (surface[i] and surface[j]) or j in excluded:
                continue
            d = ref[j, :3] - ref[i, :3]
            d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
            first = i if rank[i] < rank[j] else j
            if d2 < 9.0 * L * L and d2 < (2.0 * ref[first, 3]) ** 2:
                out.append((i - lo, j - lo))
    return np.array(out, dtype=np.intp).reshape(-1, 2)


def test_all_pairs_exclusion_rows_span_several_words():
    # With AVX-512 the all-pairs test drops excluded pairs by a row of bits per surface
    # voxel (64 to a word, each vector of 8 candidates read across a word's end where it
    # falls there): on sparse 7^3 bodies of about 200 surface voxels, walking and falling on
    # the floor, its lists equal the spatial hash's (which walks the exclusion lists),
    # step for step
    from softgym.engine import _contact

    rng = np.random.default_rng(4)
    bodies = [Body.uniform((rng.random((7, 7, 7)) < 0.6).astype(float), cte=0.01)
              for _ in range(2)]
    runs = []
    for limit in (10**9, 0):  # every robot all-pairs, then every robot hashed
        old = _contact.all_pairs_max(limit)
        try:
            sim = Simulation(bodies, SimConfig(self_collision=True), n_threads=1)
            a = sim._a  # more than two words of 64 surface voxels a row
            for r in range(2):
                lo, hi = int(a["vox_start"][r]), int(a["vox_start"][r + 1])
                assert int(a["surface"][lo:hi].sum()) > 128
            lists = []
            for _ in range(6):
                sim.advance(0.1)
                lists.append([sim.collision_candidates(r) for r in range(2)])
            runs.append(lists)
        finally:
            _contact.all_pairs_max(old)
    assert all(sum(len(step[r]) for step in runs[0]) > 100 for r in range(2))
    for step_a, step_b in zip(*runs):
        for pa, pb in zip(step_a, step_b):
            assert np.array_equal(pa, pb)


@pytest.mark.parametrize("model", ["seed", "corotational"])
def test_all_pairs_candidates_equal_the_spatial_hash(model):
    # a small robot's candidates come from testing every pair of surface
    # voxels, a large one's from the spatial hash: the same lists, step for
    # step, and the same bits (the C pulled shut, and a block of muscles of
    # unequal sizes, so the seed's rule picks the first voxel's size)
    from softgym.engine import _contact

    bodies = [_c_shape_pulled_shut(True).bodies[0], reference_robot(4, cte=0.03)]
    cfg = SimConfig(self_collision=True, model=model, init_time=0.0, gravity=0.0, floor=False,
                    global_damping=0.05)  # fmt: skip
    runs = []
    for limit in (10**9, 0):  # every robot all-pairs, then every robot hashed
        old = _contact.all_pairs_max(limit)
        try:
            sim = Simulation(bodies, cfg, n_threads=1)
            _pull_shut(sim, 0)
            lists = []
            for _ in range(12):
                sim.advance(0.1)
                lists.append([sim.collision_candidates(r) for r in range(2)])
            runs.append((sim, lists))
        finally:
            _contact.all_pairs_max(old)
    (sim_a, lists_a), (sim_b, lists_b) = runs
    for r in range(2):  # both robots have candidates at some step
        assert any(len(step[r]) for step in lists_a)
    for step_a, step_b in zip(lists_a, lists_b):
        for pa, pb in zip(step_a, step_b):
            assert np.array_equal(pa, pb)
    for r in range(2):
        assert np.array_equal(sim_a.positions(r), sim_b.positions(r))
    if model == "seed":
        for r in range(2):
            assert np.array_equal(lists_a[-1][r], _seed_rule_pairs(sim_a, r))

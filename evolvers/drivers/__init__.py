"""The searches: one run skeleton and the drivers built on it.

* :mod:`~evolvers.drivers.registry` - the drivers by name (:data:`~evolvers.drivers.registry.BACKENDS`,
  pymoo's algorithm names): the CLI's choices are read there;
* :mod:`~evolvers.drivers.base` - :class:`~evolvers.drivers.base.Driver` (construction,
  generation loop, progress, Ctrl-C, checkpoint, exact resume) and the one
  :class:`~evolvers.drivers.base.IdCounter`;
* :mod:`~evolvers.drivers.budget` - :class:`~evolvers.drivers.budget.Budget`: what stops a
  run besides its generations (simulations, robot-seconds, wall time, a target score);
* :mod:`~evolvers.drivers.runner` - :class:`~evolvers.drivers.runner.EvolutionRun`, the
  seed's loop (the native backend);
* :mod:`~evolvers.drivers.deap_runner` - the same loop on a DEAP toolbox;
* :mod:`~evolvers.drivers.pymoo_runner` - any pymoo algorithm through ask and tell
  (CMA-ES over a design vector or a brain's weights);
* :mod:`~evolvers.drivers.random_search` - random search, the baseline of every search;
* :mod:`~evolvers.drivers.qd` - MAP-Elites on pyribs (the ``.[qd]`` extra);
* :mod:`~evolvers.drivers.poet` - co-evolution of robots and terrains after Enhanced POET.

Each module is imported on demand (the DEAP, pymoo and pyribs ones need their library).
"""

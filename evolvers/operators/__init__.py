"""The genome and what a search does to it: vary and select.

* :mod:`~evolvers.operators.genome` - :class:`~evolvers.operators.genome.Individual`:
  CPPN + material genes + controller genes + age + lineage;
* :mod:`~evolvers.operators.variation` - arithmetic crossover, bounded Gaussian mutation,
  CPPN mutation, :func:`~evolvers.operators.variation.make_children`;
* :mod:`~evolvers.operators.selection` - the seed's Pareto (with age), NSGA-II, fitness
  tournament, AMSS novelty; ``SELECTORS``, the selections by name;
* :mod:`~evolvers.operators.encoding` - :class:`~evolvers.operators.encoding.CPPNVector`:
  a fixed-topology CPPN, the controller genes and a brain as one real vector (CMA-ES's).

Imports nothing else of :mod:`evolvers`. The public names are also in :mod:`evolvers`.
"""

"""What a robot is scored on and how: experiments, the evaluator, Dask, body descriptors.

* :mod:`~evolvers.evaluation.experiments` - the seed's scenarios by name
  (:class:`~evolvers.evaluation.experiments.Experiment`: task, objectives, selection, sizes);
* :mod:`~evolvers.evaluation.evaluator` - :class:`~evolvers.evaluation.evaluator.Evaluator`,
  the one evaluator of every driver: batched calls to :func:`softgym.evaluate`, cached by
  (task, phenotype);
* :mod:`~evolvers.evaluation.distributed` - a generation split over Dask workers (the
  ``.[distributed]`` extra);
* :mod:`~evolvers.evaluation.descriptors` - body descriptors (quality-diversity archives).

Uses :mod:`evolvers.operators`; imports no driver.
"""

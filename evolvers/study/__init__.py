"""The study: the seed report's scenarios over many seeds, and its claim-by-claim report.

Apart from the drivers it uses (the library: :mod:`evolvers` and :mod:`softgym`), which
never import it:

* :mod:`evolvers.study.runs` - :class:`Study`, :class:`Scenario`, :func:`plan`,
  :func:`run_study`: every scenario x seed as an ordinary, resumable run folder
  (``softgym study``);
* the report, written from those folders alone (``softgym study report RUNS``):
  :mod:`~evolvers.study.data` (the folders as the report reads them, the seed report's
  curves), :mod:`~evolvers.study.stats` (summaries, A12, permutation and sign tests),
  :mod:`~evolvers.study.claims` (the 17 claims), :mod:`~evolvers.study.figures` and
  :mod:`~evolvers.study.report` (``README.md``, ``claims.json``).
"""

from evolvers.study.claims import claims
from evolvers.study.data import load_runs
from evolvers.study.report import write_report
from evolvers.study.runs import Study, get_study, plan, run_status, run_study

__all__ = ["Study", "claims", "get_study", "load_runs", "plan", "run_status", "run_study", "write_report"]

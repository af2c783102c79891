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

from evolvers.study.claims import Claim, claims
from evolvers.study.data import RunData, load_runs
from evolvers.study.report import write_report
from evolvers.study.runs import (
    SEED_REPORT,
    STUDIES,
    STUDY_SCHEMA,
    RunSpec,
    Scenario,
    Study,
    get_study,
    plan,
    run_one,
    run_order,
    run_status,
    run_study,
    settings_difference,
    time_to_go,
)
from evolvers.study.stats import a12, permutation_pvalue

__all__ = [
    "SEED_REPORT",
    "STUDIES",
    "STUDY_SCHEMA",
    "Claim",
    "RunData",
    "RunSpec",
    "Scenario",
    "Study",
    "a12",
    "claims",
    "get_study",
    "load_runs",
    "permutation_pvalue",
    "plan",
    "run_one",
    "run_order",
    "run_status",
    "run_study",
    "settings_difference",
    "time_to_go",
    "write_report",
]

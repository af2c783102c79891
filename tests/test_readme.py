"""Every code block of the README runs verbatim (issue 13; the runner is tests/docblocks.py).

Python blocks run as scripts and bash blocks line by line, in order, in one scratch
folder, with ``SOFTGYM_SMOKE=1`` (every evolution run cut to one generation of four
small robots). Lines that install (``pip``, venvs), run the test suite, or run
``softgym study`` (its own test, tests/evolvers/study/test_study.py) are left out. The
tutorials moved to the documentation site (issue 32), whose blocks tests/test_docs.py runs.
"""

from pathlib import Path

import pytest
from docblocks import code_blocks, run_blocks

ROOT = Path(__file__).resolve().parents[1]


def _blocks():
    return code_blocks((ROOT / "README.md").read_text())


def test_readme_has_code_blocks():
    kinds = [k for k, _ in _blocks()]
    assert kinds.count("python") >= 4 and kinds.count("bash") >= 2


@pytest.mark.slow
def test_every_readme_block_runs_verbatim(tmp_path):
    assert run_blocks(_blocks(), tmp_path, "README") >= 8

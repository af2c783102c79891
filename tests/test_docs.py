"""The documentation site (docs/): its pages are all reachable and every code block runs.

The blocks of the site's hand-written pages run verbatim, page after page in the order of
the index's table of contents, in one scratch folder (so a tutorial may continue a run an
earlier page started), with ``SOFTGYM_SMOKE=1`` (tests/docblocks.py). The generated task
pages are checked against the registry without Sphinx (docs/_ext/softgym_tasks.py).
"""

import importlib.util
import re
from pathlib import Path

import pytest
from docblocks import code_blocks, run_blocks

from softgym.envs import env_id
from softgym.tasks import KINDS

DOCS = Path(__file__).resolve().parents[1] / "docs"


def _toctree_pages(index: Path) -> list[Path]:
    """The pages an index's toctrees list, in order (those that exist)."""
    pages = []
    for block in re.findall(r"```\{toctree\}\n(.*?)```", index.read_text(), re.S):
        for line in block.splitlines():
            entry = line.strip().replace("_IF_PRESENT", "")  # conf.py: PHYSICS.md where it exists
            if entry and not entry.startswith(":"):
                page = index.parent / f"{entry}.md"
                if page.exists():
                    pages.append(page)
    return pages


def _site_pages() -> list[Path]:
    return [DOCS / "index.md", *_toctree_pages(DOCS / "index.md")]


def test_every_hand_written_page_is_in_the_toctree():
    listed = set(_site_pages())
    hand_written = {
        p for p in DOCS.rglob("*.md")
        if p.relative_to(DOCS).parts[0] not in ("_build", "tasks", "api", "study", "figures")
    }  # fmt: skip
    assert hand_written <= listed, sorted(map(str, hand_written - listed))


def test_the_site_has_code_blocks():
    kinds = [k for p in _site_pages() for k, _ in code_blocks(p.read_text())]
    assert kinds.count("python") >= 5 and kinds.count("bash") >= 5


def _generator():
    spec = importlib.util.spec_from_file_location("softgym_tasks", DOCS / "_ext" / "softgym_tasks.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_one_generated_page_per_task(tmp_path):
    written = _generator().write_pages(tmp_path)
    assert sorted(p.stem for p in written) == sorted([*KINDS, "index"])
    index = (tmp_path / "index.md").read_text()
    for name, kind in KINDS.items():
        page = (tmp_path / f"{name}.md").read_text()
        assert page.startswith(f"# {name}\n") and env_id(name) in page
        assert f"`{kind.reward}`" in page and f"]({name}.md)" in index
        for arg, opt in kind.options.items():
            assert f"| `{arg}` |" in page and opt.doc in page


@pytest.mark.slow
def test_every_site_block_runs_verbatim(tmp_path):
    ran = 0
    for page in _site_pages():
        ran += run_blocks(code_blocks(page.read_text()), tmp_path, str(page.relative_to(DOCS)))
    assert ran >= 20

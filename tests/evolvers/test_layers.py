"""evolvers is one folder per job, each importing only the folders above it.

operators <- evaluation <- recording <- drivers <- study (docs/ARCHITECTURE.md); no
module imports another's private names, nor the package root (whose imports would loop).
"""

import ast
from pathlib import Path

import evolvers

ORDER = ("operators", "evaluation", "recording", "drivers", "study")
ROOT = Path(evolvers.__file__).parent


def _evolvers_imports(path):
    """(module, imported names) of each import of evolvers in a file, at any depth."""
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("evolvers"):
            yield node.module, [a.name for a in node.names]
        elif isinstance(node, ast.Import):
            yield from ((a.name, []) for a in node.names if a.name.startswith("evolvers"))


def test_every_module_lives_in_the_folder_of_its_job():
    assert [p.name for p in ROOT.glob("*.py")] == ["__init__.py"]
    folders = {p.name for p in ROOT.iterdir() if p.is_dir() and p.name != "__pycache__"}
    assert folders == set(ORDER)


def test_folders_import_only_those_above_them_and_no_private_names():
    for path in ROOT.glob("*/*.py"):
        folder = path.relative_to(ROOT).parts[0]
        for module, names in _evolvers_imports(path):
            parts = module.split(".")
            assert len(parts) > 1, f"{path} imports the package root ({module})"
            assert ORDER.index(parts[1]) <= ORDER.index(folder), f"{path} imports {module}"
            private = [n for n in names if n.startswith("_")]
            assert not private, f"{path} imports {private} from {module}"

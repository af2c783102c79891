"""The helpers in this folder (``evolver_helpers``, ``poet_helpers``) are importable from its subfolders' tests."""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

"""Test-wide setup: the shared helpers in this folder (e.g. ``fuzzing``) are importable from any test."""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

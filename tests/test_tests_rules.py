"""Tests use the benchmark scripts as a user does, as child processes: none imports one.

A test that imported ``benchmarks/*.py`` (through ``sys.path`` or
``importlib.util.spec_from_file_location``) would make the scripts a library
whose names the tests pin; running them keeps the command line the contract.
"""

import ast
from pathlib import Path

TESTS = Path(__file__).resolve().parent


def _mentions_benchmarks(node):
    """True when a call's arguments name the benchmarks folder (a string or BENCH)."""
    for n in ast.walk(node):
        if isinstance(n, ast.Constant) and isinstance(n.value, str) and "benchmarks" in n.value:
            return True
        if isinstance(n, ast.Name) and n.id in {"BENCH", "BENCHMARKS"}:
            return True
    return False


def test_no_test_imports_a_benchmark_script():
    offenders = []
    for path in TESTS.rglob("*.py"):
        tree = ast.parse(path.read_text())
        for node in ast.walk(tree):
            if not isinstance(node, ast.Call):
                continue
            func = node.func
            name = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", "")
            if name in {"spec_from_file_location", "insert", "append"} and _mentions_benchmarks(node):
                offenders.append(f"{path.relative_to(TESTS)}:{node.lineno}")
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("benchmarks"):
                offenders.append(f"{path.relative_to(TESTS)}:{node.lineno}")
    assert not offenders, f"tests that import benchmark scripts: {offenders}"

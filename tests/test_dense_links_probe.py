"""benchmarks/dense_links_probe.py: the dense-lattice probe still builds against the engine's
headers and agrees with the engine's passes bit for bit.

Run as a user runs it (a child process); skipped without a C compiler or off x86-64.
"""

from c_probes import needs_cc_on_x86_64, run_probe  # tests/c_probes.py


@needs_cc_on_x86_64
def test_the_probe_builds_and_matches_the_engine_bit_for_bit():
    res = run_probe("dense_links_probe.py", "--n", "3", "--fill", "0.8")
    assert res.returncode == 0, res.stdout + res.stderr
    runs = [line for line in res.stdout.splitlines() if line.startswith("  bit identity:")]
    assert runs, res.stdout  # at least the portable build ran
    for line in runs:
        assert "differing 0 of" in line and "components differing 0 of" in line, line

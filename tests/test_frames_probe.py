"""benchmarks/frames_probe.py: the frames-pass probe still builds against the engine's
headers, and its pass agrees with the engine's compiled one bit for bit.

Run as a user runs it (a child process); skipped without a C compiler or off x86-64.
"""

from c_probes import needs_cc_on_x86_64, run_probe  # tests/c_probes.py


@needs_cc_on_x86_64
def test_the_probe_builds_and_matches_the_engine_bit_for_bit():
    res = run_probe("frames_probe.py", "--chunks", "2", "--reps", "3", "--large", "0", "0.5")
    assert res.returncode == 0, res.stdout + res.stderr
    timed = [line for line in res.stdout.splitlines() if "cycles per 16 links" in line]
    assert len(timed) >= 2, res.stdout  # at least one build ran both shares
    checked = [line for line in timed if "bit identity:" in line]
    assert checked, res.stdout  # at least the build that matches the running kernel
    for line in checked:
        assert "differing 0 of" in line and "of 0 values" not in line, line


def test_the_probe_refuses_bad_shares():
    res = run_probe("frames_probe.py", "--large", "1.5", timeout=120)
    assert res.returncode == 2 and "--large" in res.stderr

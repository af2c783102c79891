"""The seed kernel's C passes vectorise (a guard, not a timing).

A refactor that keeps every bit can still stop GCC from vectorising a loop:
the geometry pass once ran scalar for a whole session (twice its cycles)
because its quaternion reached the matrix formula as a pointer plus an
offset, which GCC 12 found "not suitable for gather load". Each pass of
``include/softgym_seed.h``, ``include/softgym_orient.h`` and ``include/softgym_pairs.h``
is compiled here
alone, with the flags of the x86-64-v3 kernel build (setup.py), and GCC's
vectorisation report must name a vectorised loop in it. Skipped where the
compiler is not GCC or cannot target x86-64-v3.
"""

import shutil
import subprocess
from pathlib import Path

import pytest

import softgym.engine

INCLUDE = Path(softgym.engine.__file__).parent / "include"
FLAGS = ["-O3", "-ffp-contract=fast", "-fno-math-errno", "-fno-trapping-math",
         "-march=x86-64-v3", "-fopt-info-vec-optimized"]  # fmt: skip

# one call per pass (the headers' functions are static: only the called one is compiled)
PASSES = {
    "softgym_seed_geom": "softgym_seed_geom(ax, 0, n, n, ip, ip, d, d, d, o);",
    "softgym_seed_frames": "softgym_seed_frames(0, n, 0.01, 0.002, d, d, d, d, d, d, d, d, d, d, "
                           "o, o, o, o, o, o, o, o, o, o, o, o);",
    "softgym_seed_forces": "softgym_seed_forces(0, n, n, 0.01, 0.1, 0.05, 1e4, cin, d, d, d, d, d, d, "
                           "o, out);",
    "softgym_seed_frames32": "softgym_seed_frames32(0, n, n, 0.01f, 0.9988f, d, fo);",
    "softgym_seed_forces32": "softgym_seed_forces32(0, n, n, 0.01f, 0.1f, 0.05f, 1e4f, fin, d, d, fc, fc, "
                             "fc, fc, fo[0], out);",
    "softgym_seed_modes": "return (long)softgym_seed_modes(0, n, n, 0.3, 0.99, 0.98, 0.05, 1.3, "
                          "0.055, 1.43, lf, lf, o);",
    "softgym_seed_quats": "softgym_seed_quats(0, n, n, 1e-4, d, d, o);",
    "softgym_corot_quats": "softgym_corot_quats(0, n, n, 1e-4, d, d, o);",
    "softgym_pair_hits": "softgym_pair_hits(ax, 0, n, d, d, d, d, ip, 1e-4, lf);",
}


def _gcc():
    cc = shutil.which("gcc") or shutil.which("cc")
    if cc is None:
        return None
    version = subprocess.run([cc, "--version"], capture_output=True, text=True).stdout.lower()
    is_gcc = "clang" not in version and ("gcc" in version or "free software" in version)
    return cc if is_gcc else None


@pytest.mark.parametrize("name", sorted(PASSES))
def test_each_seed_pass_vectorises(name, tmp_path):
    cc = _gcc()
    if cc is None:
        pytest.skip("the vectorisation report is GCC's")
    src = tmp_path / "pass.c"
    src.write_text(
        "#include <stddef.h>\n"
        "typedef long Py_ssize_t;\n"  # Python.h's, which Cython includes first
        '#include "softgym_seed.h"\n'
        '#include "softgym_orient.h"\n'
        '#include "softgym_pairs.h"\n'
        "long run(int ax, Py_ssize_t n, const Py_ssize_t *ip, const double *d, double *o,\n"
        "         long long *lf, const double *const *cin, double *const *out,\n"
        "         const float *fc, float *const *fo, const float *const *fin)\n"
        "{\n"
        f"    {PASSES[name]}\n"
        "    return 0;\n"
        "}\n"
    )
    res = subprocess.run([cc, *FLAGS, f"-I{INCLUDE}", "-c", str(src), "-o", str(tmp_path / "pass.o")],
                         capture_output=True, text=True)  # fmt: skip
    if res.returncode != 0 and "x86-64-v3" in res.stderr:
        pytest.skip("the compiler cannot target x86-64-v3")
    assert res.returncode == 0, res.stderr
    assert "implicit declaration" not in res.stderr, res.stderr  # the pass is where we look
    vectorised = [line for line in res.stderr.splitlines()
                  if "loop vectorized" in line
                  and any(h in line for h in ("softgym_seed", "softgym_orient.h", "softgym_pairs.h"))]  # fmt: skip
    assert vectorised, f"{name}: GCC vectorised no loop:\n{res.stderr[-2000:]}"

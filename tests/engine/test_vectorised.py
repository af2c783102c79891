"""The seed kernel's C passes vectorise (a guard, not a timing).

A refactor that keeps every bit can still stop GCC from vectorising a loop:
the geometry pass once ran scalar for a whole session (twice its cycles)
because its quaternion reached the matrix formula as a pointer plus an
offset, which GCC 12 found "not suitable for gather load". Each pass of
``include/softgym_seed.h``, ``include/softgym_orient.h`` and ``include/softgym_pairs.h``
is compiled here
alone, with the flags of the x86-64-v3 kernel build (setup.py), and GCC's
vectorisation report must name a vectorised loop in it. The geometry pass is
vectorised by hand where the build has AVX (its loads; the arithmetic is the
scalar formula's macro on vectors): there the hand path must be compiled in, and
a harness checks it against the formula link by link, bit for bit; so does one
for the corotational link kernel (include/softgym_corot.h). Skipped where
the compiler is not GCC or cannot target x86-64-v3.
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
    "softgym_seed_geom": "softgym_seed_geom(ax, 0, n, n, ip, ip, n, d, d, d, n, d, o, o, "
                         "(float *)0);",
    "softgym_seed_frames": "softgym_seed_frames(0, n, 0.01, 0.002, d, d, d, d, d, d, d, d, d, d, "
                           "o, o, o, o, o, o, o, o, o, o, o, o);",
    "softgym_seed_forces": "softgym_seed_forces(0, n, n, 0.01, 0.1, 0.05, 1e4, d, n, d, d, d, d, d, "
                           "d, d, o, o);",
    "softgym_seed_frames32": "softgym_seed_frames32(0, n, n, 0.01f, 0.9988f, d, fo[0]);",
    "softgym_seed_forces32": "softgym_seed_forces32(0, n, n, 0.01f, 0.1f, 0.05f, 1e4f, fc, 0, d, d, "
                             "d, fc, fc, fc, fc, fo[0], fo[1]);",
    "softgym_seed_modes": "return (long)softgym_seed_modes(0, n, n, 0.3, 0.99, 0.98, 0.05, 1.3, "
                          "0.055, 1.43, lf, lf, o);",
    "softgym_seed_quats": "softgym_seed_quats(0, n, n, 1e-4, d, d, o, 1);",  # (the Newton form)
    "softgym_seed_quats exact": "softgym_seed_quats(0, n, n, 1e-4, d, d, o, 0);",
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


HEADERS = ("softgym_seed.h", "softgym_orient.h", "softgym_pairs.h", "softgym_corot.h")
REPORTED = (*HEADERS, "softgym_seed_forces.h")  # included by softgym_seed.h


def _compile_pass(call, march, guard, tmp_path):
    """GCC's vectorisation report (stderr) of ``call`` compiled alone, with the kernel
    build's flags for ``march``, after the headers and the preprocessor lines ``guard``."""
    cc = _gcc()
    if cc is None:
        pytest.skip("the vectorisation report is GCC's")
    src = tmp_path / "pass.c"
    src.write_text(
        "#include <stddef.h>\n"
        "typedef long Py_ssize_t;\n"  # Python.h's, which Cython includes first
        + "".join(f'#include "{h}"\n' for h in HEADERS)
        + guard
        + "long run(int ax, Py_ssize_t n, const Py_ssize_t *ip, const double *d, double *o,\n"
        "         long long *lf, const float *fc, float *const *fo)\n"
        "{\n"
        f"    {call}\n"
        "    return 0;\n"
        "}\n"
    )
    flags = [f if not f.startswith("-march") else f"-march={march}" for f in FLAGS]
    res = subprocess.run([cc, *flags, f"-I{INCLUDE}", "-c", str(src), "-o", str(tmp_path / "pass.o")],
                         capture_output=True, text=True)  # fmt: skip
    if res.returncode != 0 and march in res.stderr:
        pytest.skip(f"the compiler cannot target {march}")
    assert res.returncode == 0, res.stderr
    assert "implicit declaration" not in res.stderr, res.stderr  # the pass is where we look
    return [line for line in res.stderr.splitlines()
            if "loop vectorized" in line and any(h in line for h in REPORTED)]  # fmt: skip


@pytest.mark.parametrize("name", sorted(PASSES))
def test_each_seed_pass_vectorises(name, tmp_path):
    # the geometry's loop is vectorised by hand with AVX (its remainder is the compiler's)
    hand = ("#ifndef SOFTGYM_VLANES\n#error the hand-vectorised geometry is not compiled in\n"
            "#endif\n") if name == "softgym_seed_geom" else ""  # fmt: skip
    vectorised = _compile_pass(PASSES[name], "x86-64-v3", hand, tmp_path)
    assert vectorised or hand, f"{name}: GCC vectorised no loop"


# the hand-vectorised passes in the portable build (x86-64 without AVX: SSE2): the seed
# geometry's 4 lanes on GCC's vectors (SOFTGYM_PORTABLE_LANES; its harness below holds them
# to the formula), the corotational links the compiler's loop, which GCC must vectorise
@pytest.mark.parametrize("name", ["softgym_seed_geom", "softgym_corot_links"])
def test_the_portable_build_vectorises_the_hand_vectorised_passes(name, tmp_path):
    if name == "softgym_seed_geom":
        call = PASSES["softgym_seed_geom"]
        guard = "#ifndef SOFTGYM_PORTABLE_LANES\n#error the portable lanes are not compiled in\n#endif\n"
    else:
        call = ("softgym_corot_links(ax, 0, n, n, 100.0, ip, ip, d, d, d, d, d, d, d, d, d, d, d, "
                "(const double *)0, 0, 0, o);")  # fmt: skip
        guard = "#if SOFTGYM_COROT_V4\n#error the portable build keeps the compiler's loop\n#endif\n"
    vectorised = _compile_pass(call, "x86-64", guard, tmp_path)
    assert vectorised or name == "softgym_seed_geom", f"{name}: GCC vectorised no loop"


# the single-precision links' passes in the portable build: every copy of each one's main
# loop (forces: 4, by mode and voxel 2's force; frames: 2, all small-angle or mixed; push:
# the turn of each side along each axis, 6) vectorised. Each took a condition from a double
# row, or a select before a store or load, that SSE2 cannot make a vector of, and ran scalar
PORTABLE_FLOAT = {  # the call, and the function whose first loop is the main one
    "softgym_seed_forces32": (PASSES["softgym_seed_forces32"], "softgym_seed_forces.h",
                              "SOFTGYM_ALWAYS_INLINE void SOFTGYM_FCAT(SOFTGYM_FNAME, _impl)", 4),
    "softgym_seed_frames32": (PASSES["softgym_seed_frames32"], "softgym_seed.h",
                              "SOFTGYM_ALWAYS_INLINE int softgym_seed_frames32_impl(", 2),
    "softgym_seed_push32": ("softgym_seed_push32(ax, 0, n, ip, ip, fc, fc, d, fo[0], n);",
                            "softgym_seed.h",
                            "SOFTGYM_ALWAYS_INLINE void softgym_seed_push32_links(", 6),
}


def _first_loop_line(header: str, function: str) -> int:
    """The line number of the first ``for (`` after ``function``'s definition in ``header``."""
    lines = (INCLUDE / header).read_text().splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith(function))
    return next(i for i in range(start, len(lines)) if "for (" in lines[i]) + 1


@pytest.mark.parametrize("name", sorted(PORTABLE_FLOAT))
def test_the_portable_build_vectorises_every_copy_of_the_float_passes(name, tmp_path):
    call, header, function, copies = PORTABLE_FLOAT[name]
    at = f"{header}:{_first_loop_line(header, function)}:"
    lines = _compile_pass(call, "x86-64", "", tmp_path)
    # each copy's main loop in 16-byte vectors (an epilogue may add an 8-byte one)
    main = [line for line in lines if at in line and "16 byte vectors" in line]
    assert len(main) >= copies, f"{at} vectorised {len(main)} times of {copies}:\n" + "\n".join(lines)


def _c_harness(header: str, body: str) -> str:
    """A C harness's source: the C headers it uses, Python.h's ``Py_ssize_t`` (which Cython
    includes first), the kernel header ``header``, ``urand()`` (uniform in [-0.5, 0.5]) and
    ``urand_quat(q)`` (a random unit quaternion; ``URAND_ROT(R)`` its matrix),
    ``urand_both``, ``link_pattern`` and ``rows_differ`` (the scatters' links, force and
    moment rows), ``urand_voxels`` (the geometry harnesses' voxels and their rows), then
    ``body``."""
    return ("#include <stdio.h>\n#include <stdlib.h>\n#include <string.h>\n"
            "typedef long Py_ssize_t;\n"
            f'#include "{header}"\n'
            "static double urand(void) { return rand() / (double)RAND_MAX - 0.5; }\n"
            "static inline void urand_quat(double *q) {  /* a random unit quaternion */\n"
            "    double s = 0.0;\n"
            "    for (int k = 0; k < 4; k++) { q[k] = urand(); s += q[k] * q[k]; }\n"
            "    for (int k = 0; k < 4; k++) q[k] /= sqrt(s);\n"
            "}\n"
            "#define URAND_ROT(R) do { double q_[4]; urand_quat(q_); softgym_quat_matrix(q_, R); } "
            "while (0)\n"
            "static inline void urand_both(double *a, double *b, int n) {  /* a = b = random */\n"
            "    for (int k = 0; k < n; k++) a[k] = b[k] = urand();\n"
            "}\n"
            "static inline void link_pattern(int pattern, Py_ssize_t *v1, Py_ssize_t *v2, int n,\n"
            "                                int nv) {  /* 0: runs along x, 1: along y, 2: any */\n"
            "    for (int li = 0; li < n; li++) {\n"
            "        if (pattern == 0) {  /* runs of 5 links, voxel 2 the next link's voxel 1 */\n"
            "            v1[li] = li + li / 5;\n"
            "            v2[li] = v1[li] + 1;\n"
            "        } else if (pattern == 1) {  /* along y of a 6-wide lattice */\n"
            "            v1[li] = li % 30 + 36 * (li / 30);\n"
            "            v2[li] = v1[li] + 6;\n"
            "        } else {  /* any voxels, distinct within the link */\n"
            "            v1[li] = rand() % nv;\n"
            "            v2[li] = (v1[li] + 1 + rand() % (nv - 1)) % nv;\n"
            "        }\n"
            "    }\n"
            "}\n"
            "static inline void urand_voxels(int nv, double *pos, double *quat, double *sc,\n"
            "                                double *vr, int vn) {  /* nv voxels, rows vn apart */\n"
            "    for (int i = 0; i < nv; i++) {\n"
            "        urand_quat(quat + 4 * i);\n"
            "        for (int k = 0; k < 3; k++) pos[3 * i + k] = 0.01 * (i % 7 + urand());\n"
            "        sc[i] = 0.01 * (1.0 + 0.1 * urand());\n"
            "        for (int k = 0; k < 4; k++) vr[(SOFTGYM_ROW_QUAT + k) * vn + i] = quat[4 * i + k];\n"
            "        for (int k = 0; k < 3; k++) vr[(SOFTGYM_ROW_POS + k) * vn + i] = pos[3 * i + k];\n"
            "    }\n"
            "}\n"
            "static inline long rows_differ(const double *a, const double *b, int nv) {\n"
            "    long bad = 0;  /* force (lanes 0-2) and moment (4-6) of nv voxels' rows */\n"
            "    for (int i = 0; i < nv; i++)\n"
            "        for (int c = 0; c < 7; c++)\n"
            "            bad += c != 3 && memcmp(&a[SOFTGYM_FM_STRIDE * i + c],\n"
            "                                    &b[SOFTGYM_FM_STRIDE * i + c], sizeof(double)) != 0;\n"
            "    return bad;\n"
            "}\n" + body)


HARNESS = _c_harness("softgym_seed.h", r"""
/* links along each axis through softgym_seed_geom (the hand-vectorised loop with its
   three ways of loading the voxels: runs, windows of 16, gathers; and its remainder)
   against SOFTGYM_SEED_GEOM_LINK, one link at a time; and, run a chunk at a time as the
   engine does, the rotation rows it leaves for the scatter (AVX-512) against voxel 1's
   matrix, and (single-precision links, every build) the float rows of it rounded that it
   leaves for the push instead. The runs and windows load the voxel rows vr (quaternions in rows
   SOFTGYM_ROW_QUAT.., positions in SOFTGYM_ROW_POS.., VN apart); in the builds whose seed step keeps its state there
   (SOFTGYM_STATE_ROWS) every path does, and the records it is given are NaN (stale during
   that step); elsewhere they are the records' copy */
enum { VN = 216 };
static double rr[SOFTGYM_CHUNK_ROWS * SOFTGYM_CHUNK_STRIDE], vr[SOFTGYM_VOXEL_ROWS * VN];
static float rf[9 * SOFTGYM_CHUNK_FSTRIDE];
static double pos_rec[3 * VN], quat_rec[4 * VN];  /* the records softgym_seed_geom gets */
SOFTGYM_ALWAYS_INLINE long check_ax(const int ax, Py_ssize_t n, const Py_ssize_t *v1,
                                    const Py_ssize_t *v2, Py_ssize_t nv, const double *pos,
                                    const double *quat, const double *sc, double *o, double *r)
{
    long bad = 0;
    for (Py_ssize_t c0 = 0; c0 < n; c0 += SOFTGYM_CHUNK_LINKS) {
        Py_ssize_t c1 = c0 + SOFTGYM_CHUNK_LINKS < n ? c0 + SOFTGYM_CHUNK_LINKS : n;
        double *R = rr + SOFTGYM_SEED_R_ROWS * SOFTGYM_CHUNK_STRIDE;
        softgym_seed_geom(ax, c0, c1, n, v1, v2, nv, pos_rec, quat_rec, vr, VN, sc, o, R - c0,
                          (float *)0);
        for (Py_ssize_t li = c0; li < c1 && SOFTGYM_SEED_R_USED; li++) {  /* (where written) */
            double m[9];
            softgym_quat_matrix(quat + 4 * v1[li], m);
            for (int k = 0; k < 9; k++)
                bad += memcmp(&m[k], R + k * SOFTGYM_CHUNK_STRIDE + li - c0, sizeof(double)) != 0;
        }
        softgym_seed_geom(ax, c0, c1, n, v1, v2, nv, pos_rec, quat_rec, vr, VN, sc, o, (double *)0,
                          rf - c0);
        for (Py_ssize_t li = c0; li < c1; li++) {  /* (every build writes these) */
            double m[9];
            softgym_quat_matrix(quat + 4 * v1[li], m);
            for (int k = 0; k < 9; k++) {
                float mk = (float)m[k];
                bad += memcmp(&mk, rf + k * SOFTGYM_CHUNK_FSTRIDE + li - c0, sizeof(float)) != 0;
            }
        }
    }
    softgym_seed_geom(ax, 0, n, n, v1, v2, nv, pos_rec, quat_rec, vr, VN, sc, o, (double *)0,
                      (float *)0);
    SOFTGYM_SEED_GEOM_AXIS(ax);
    SOFTGYM_SEED_GEOM_OUT(r, n);
    for (Py_ssize_t li = 0; li < n; li++) {
        Py_ssize_t i = v1[li], j = v2[li];
        const double *qi = quat + 4 * i, *qj = quat + 4 * j;
        SOFTGYM_SEED_GEOM_LINK(li, pos[3 * j] - pos[3 * i], pos[3 * j + 1] - pos[3 * i + 1],
                               pos[3 * j + 2] - pos[3 * i + 2], qi[0], qi[1], qi[2], qi[3],
                               qj[0], qj[1], qj[2], qj[3], sc[i], sc[j]);
    }
    for (Py_ssize_t k = 0; k < 10 * n; k++)
        bad += memcmp(o + k, r + k, sizeof(double)) != 0;
    return bad;
}
int main(void)
{
    enum { NV = 200, N = 203 };  /* N: not a multiple of the lanes */
    static double pos[3 * NV], quat[4 * NV], sc[NV], o[10 * N], r[10 * N];
    static Py_ssize_t v1[N], v2[N];
    long bad = 0;
    urand_voxels(NV, pos, quat, sc, vr, VN);
    for (int i = 0; i < NV; i++) {
        for (int k = 0; k < 3; k++) pos_rec[3 * i + k] = SOFTGYM_STATE_ROWS ? NAN : pos[3 * i + k];
        for (int k = 0; k < 4; k++) quat_rec[4 * i + k] = SOFTGYM_STATE_ROWS ? NAN : quat[4 * i + k];
    }
    for (int pattern = 0; pattern < 3; pattern++) {
        for (int li = 0; li < N; li++) {
            if (pattern == 0) {  /* random voxels: gathers */
                v1[li] = rand() % NV;
                v2[li] = (v1[li] + 1 + rand() % (NV - 1)) % NV;
            } else if (pattern == 1) {  /* runs of consecutive voxels, to the last voxel */
                v1[li] = li % (NV - 7);
                v2[li] = v1[li] + 7;
            } else {  /* a lattice row's links with gaps: windows of 16 */
                v1[li] = (li + li / 5) % (NV - 1);
                v2[li] = v1[li] + 1;
            }
        }
        bad += check_ax(0, N, v1, v2, NV, pos, quat, sc, o, r);
        bad += check_ax(1, N, v1, v2, NV, pos, quat, sc, o, r);
        bad += check_ax(2, N, v1, v2, NV, pos, quat, sc, o, r);
    }
    printf("%ld\n", bad);
    return 0;
}
""")


COROT_HARNESS = _c_harness("softgym_corot.h", r"""
/* links along each axis through softgym_corot_links (its 8-lane paths where the build has
   AVX-512: voxel runs, a window of 16 voxels, gathers; its 4-lane gathers; its remainder),
   with the voxels' rows (the step loop's state, the matrices from softgym_corot_rows),
   against SOFTGYM_COROT_LINK_T on doubles, one link at a time, for the three link patterns
   of link_pattern */
enum { NV = 260, N = 203 };  /* N: not a multiple of the lanes */
static double pos[3 * NV], vel[3 * NV], av[3 * NV], quat[4 * NV], rot[9 * NV], sc[NV];
static double vr[SOFTGYM_VOXEL_ROWS * NV];
static double ka[N], ca[N], kb[N], cb[N], kt[N], ct[N], o[10 * N], r[10 * N];
static Py_ssize_t v1[N], v2[N];
SOFTGYM_ALWAYS_INLINE long check_ax(const int ax)
{
    const int p = (ax + 1) % 3, q = (ax + 2) % 3;
    const double inv_L = 100.0;
    softgym_corot_links(ax, 0, N, N, inv_L, v1, v2, pos, vel, av, rot, sc, ka, ca, kb, cb, kt,
                        ct, vr, NV, NV, o);
    double *o_ext = r, *o_fx = r + N, *o_fy = r + 2 * N, *o_fz = r + 3 * N, *o_m1x = r + 4 * N;
    double *o_m1y = r + 5 * N, *o_m1z = r + 6 * N, *o_m2x = r + 7 * N, *o_m2y = r + 8 * N;
    double *o_m2z = r + 9 * N;
    for (Py_ssize_t li = 0; li < N; li++) {
        Py_ssize_t i = v1[li], j = v2[li];
        SOFTGYM_COROT_LINK_T(double, sqrt, fabs, SOFTGYM_PUT1, SOFTGYM_COROT_IDX, li, ax, p, q,
                             inv_L, pos[3 * j] - pos[3 * i], pos[3 * j + 1] - pos[3 * i + 1],
                             pos[3 * j + 2] - pos[3 * i + 2], vel[3 * j] - vel[3 * i],
                             vel[3 * j + 1] - vel[3 * i + 1], vel[3 * j + 2] - vel[3 * i + 2],
                             sc[i], sc[j], (rot + 9 * i), (rot + 9 * j), av[3 * i],
                             av[3 * i + 1], av[3 * i + 2], av[3 * j], av[3 * j + 1],
                             av[3 * j + 2], ka[li], ca[li], kb[li], cb[li], kt[li], ct[li]);
    }
    long bad = 0;
    for (Py_ssize_t k = 0; k < 10 * N; k++)
        bad += memcmp(o + k, r + k, sizeof(double)) != 0;
    return bad;
}
int main(void)
{
    for (int i = 0; i < NV; i++) {
        urand_quat(quat + 4 * i);
        softgym_quat_matrix(quat + 4 * i, rot + 9 * i);  /* as the voxel update stores it */
        for (int k = 0; k < 3; k++) {
            pos[3 * i + k] = 0.01 * (i % 7 + urand());
            vel[3 * i + k] = urand();
            av[3 * i + k] = 10.0 * urand();
        }
        sc[i] = 0.01 * (1.0 + 0.1 * urand());
    }
    /* the step loop's state rows, and the matrices softgym_corot_rows derives from them */
    for (int i = 0; i < NV; i++) {
        for (int k = 0; k < 3; k++) {
            vr[(SOFTGYM_ROW_POS + k) * NV + i] = pos[3 * i + k];
            vr[(SOFTGYM_ROW_VEL + k) * NV + i] = vel[3 * i + k];
            vr[(SOFTGYM_ROW_AV + k) * NV + i] = av[3 * i + k];
        }
        for (int k = 0; k < 4; k++)
            vr[(SOFTGYM_ROW_QUAT + k) * NV + i] = quat[4 * i + k];
    }
    softgym_corot_rows(0, NV, NV, vr);
    for (int li = 0; li < N; li++) {
        ka[li] = 1e4 * (1.0 + urand()), ca[li] = 1.0 + urand(), kb[li] = 0.1 * (1.0 + urand());
        cb[li] = 1e-4 * (1.0 + urand()), kt[li] = 0.05 * (1.0 + urand());
        ct[li] = 1e-5 * (1.0 + urand());
    }
    long bad = 0;
    for (int pattern = 0; pattern < 3; pattern++) {
        link_pattern(pattern, v1, v2, N, NV);
        bad += check_ax(0) + check_ax(1) + check_ax(2);
    }
    printf("%ld\n", bad);
    return 0;
}
""")


def _run_harness(level, text, tmp_path):
    """Compile ``text`` with the kernel build's flags for ``level`` and run it: its output."""
    cc = _gcc()
    if cc is None:
        pytest.skip("built with GCC's flags")
    cpu = Path("/proc/cpuinfo").read_text() if Path("/proc/cpuinfo").exists() else ""
    if ("avx512f" if level == "x86-64-v4" else "avx2") not in cpu:
        pytest.skip(f"this CPU cannot run {level}")
    src = tmp_path / "harness.c"
    src.write_text(text)
    exe = tmp_path / "harness"
    flags = [f if not f.startswith("-march") else f"-march={level}" for f in FLAGS[:-1]]
    res = subprocess.run([cc, *flags, f"-I{INCLUDE}", str(src), "-o", str(exe), "-lm"],
                         capture_output=True, text=True)  # fmt: skip
    if res.returncode != 0 and level in res.stderr:
        pytest.skip(f"the compiler cannot target {level}")
    assert res.returncode == 0, res.stderr
    return subprocess.run([str(exe)], capture_output=True, text=True, check=True).stdout.strip()


@pytest.mark.parametrize("level", ["x86-64-v3", "x86-64-v4"])
def test_hand_vectorised_corotational_kernel_is_the_formula_bit_for_bit(level, tmp_path):
    out = _run_harness(level, COROT_HARNESS, tmp_path)
    assert out == "0", f"{out} of {3 * 3 * 10 * 203} link outputs differ"


@pytest.mark.parametrize("level", ["x86-64", "x86-64-v3", "x86-64-v4"])
def test_hand_vectorised_geometry_is_the_formula_bit_for_bit(level, tmp_path):
    out = _run_harness(level, HARNESS, tmp_path)
    assert out == "0", f"{out} of {3 * 3 * 10 * 203} geometry values differ"


SCATTER_HARNESS = _c_harness("softgym_seed.h", r"""
/* one chunk's links scattered by softgym_seed_scatter (with AVX-512: blocks of 8 turned in
   the lanes with the geometry's rotation rows, the links before and after them one by
   one) against softgym_seed_scatter_links (every link one by one, voxel 1's matrix from
   rot): the voxels' forces and moments (lanes 0-2 and 4-6 of their rows; 3 and 7 are
   padding) */
enum { NV = 300, N = SOFTGYM_CHUNK_LINKS, FM = SOFTGYM_FM_STRIDE * NV };
static double fm_a[FM] __attribute__((aligned(64))), fm_b[FM] __attribute__((aligned(64)));
static double rot[9 * NV], neg2[N];
static double chunk[SOFTGYM_CHUNK_ROWS * SOFTGYM_CHUNK_STRIDE] __attribute__((aligned(64)));
static Py_ssize_t v1[N], v2[N];
SOFTGYM_ALWAYS_INLINE long check_ax(const int ax, Py_ssize_t lo, Py_ssize_t hi)
{
    for (int k = 0; k < 12; k++)
        for (int li = 0; li < SOFTGYM_CHUNK_STRIDE; li++)
            chunk[k * SOFTGYM_CHUNK_STRIDE + li] = urand();
    for (Py_ssize_t li = 0; li < N; li++) {
        neg2[li] = rand() % 3 == 0 ? 0.0 : 1.0;
        for (int k = 0; k < 9; k++)
            chunk[(SOFTGYM_SEED_R_ROWS + k) * SOFTGYM_CHUNK_STRIDE + li] = rot[9 * v1[li] + k];
    }
    urand_both(fm_a, fm_b, FM);
    softgym_seed_scatter(ax, lo, hi, v1, v2, rot, chunk, neg2, fm_a, fm_a + 4);
    SOFTGYM_BY_AXIS(ax, softgym_seed_scatter_links, lo, hi, v1, v2, rot, chunk, neg2, fm_b,
                    fm_b + 4);
    return rows_differ(fm_a, fm_b, NV);
}
int main(void)
{
    for (int i = 0; i < NV; i++) {
        URAND_ROT(rot + 9 * i);
    }
    long bad = 0;
    for (int pattern = 0; pattern < 3; pattern++) {
        link_pattern(pattern, v1, v2, N, NV);
        for (int ax = 0; ax < 3; ax++) {
            bad += check_ax(ax, 0, N);
            /* links one by one before and after the blocks */
            bad += check_ax(ax, 3, N - 5);
        }
    }
    printf("%ld\n", bad);
    return 0;
}
""")


PUSH_HARNESS = _c_harness("softgym_seed.h", r"""
/* the single-precision links' push (softgym_seed_push32: with AVX-512 blocks of 16 links
   turned in float lanes and added to the voxels' float rows in windows of 16 voxels)
   against softgym_seed_push32_links (each block's side turned in a loop, then added link by
   link), and against the turn and the sums written out in double from the same floats (each voxel's contributions in the push's order: per block of 16 links
   from the run's start, voxel 1's then voxel 2's; a float turn within 1e-5 of it). Links
   of a lattice's x runs (5 of 6 voxels), y runs (30, then a gap), runs of 16 and more,
   random ascending voxels (sparse bodies: gaps past the windows' reach), starting anywhere
   and ending mid-block; voxel rows in a robot's scratch (a multiple of 16 floats apart,
   on cache lines) */
enum { NV = 420, N = SOFTGYM_CHUNK_LINKS, LFS = 432, FS = SOFTGYM_CHUNK_FSTRIDE };
static float lf_a[6 * LFS + 64] __attribute__((aligned(64)));
static float lf_b[6 * LFS + 64] __attribute__((aligned(64)));
static double ref[6 * NV], rot[9 * NV], neg2[N + 16];
static float rows[SOFTGYM_CHUNK_FROWS * FS] __attribute__((aligned(64)));
static Py_ssize_t v1[N + 16], v2[N + 16];
static long bad_sums, far;
static void links(int pattern, int offset)
{
    int at = offset;
    for (int li = 0; li < N; li++) {
        if (pattern == 0) {  /* x runs: 5 links, a voxel skipped */
            v1[li] = at + li + li / 5;
            v2[li] = v1[li] + 1;
        } else if (pattern == 1) {  /* y runs of 30 in a 6 x 6 layer */
            v1[li] = at + li % 30 + 36 * (li / 30);
            v2[li] = v1[li] + 6;
        } else if (pattern == 2) {  /* z: one long run */
            v1[li] = at + li;
            v2[li] = v1[li] + 36;
        } else {  /* ascending, gaps of 1-6 voxels (some blocks span more than 3 windows) */
            at += 1 + rand() % 6;
            v1[li] = at;
            v2[li] = at + 1 + rand() % 3;
        }
    }
}
static long check(int ax, Py_ssize_t lo, Py_ssize_t hi)
{
    for (int k = 0; k < SOFTGYM_CHUNK_FROWS * FS; k++)
        rows[k] = (float)urand();
    for (Py_ssize_t li = 0; li < N; li++) {
        neg2[li] = rand() % 3 == 0 ? 0.0 : 1.0;
        for (int k = 0; k < 9; k++)
            rows[(SOFTGYM_CHUNK_FR + k) * FS + li] = (float)rot[9 * v1[li] + k];
    }
    for (int k = 0; k < 6 * LFS + 64; k++)
        lf_a[k] = lf_b[k] = 0.0f;
    for (int k = 0; k < 6 * NV; k++)
        ref[k] = 0.0;
    const float *of = rows + SOFTGYM_CHUNK_FOUT * FS, *rf = rows + SOFTGYM_CHUNK_FR * FS;
    softgym_seed_push32(ax, lo, hi, v1, v2, rf, of, neg2, lf_a, LFS);
    for (Py_ssize_t b0 = lo; b0 < hi; b0 += 16) {
        Py_ssize_t e = hi - b0 < 16 ? hi : b0 + 16;
        SOFTGYM_BY_AXIS(ax, softgym_seed_push32_links, 1, b0, e, v1, v2, rf, of, neg2, lf_b, LFS);
        SOFTGYM_BY_AXIS(ax, softgym_seed_push32_links, 2, b0, e, v1, v2, rf, of, neg2, lf_b, LFS);
    }
    long bad = 0;
    for (int k = 0; k < 6 * LFS + 64; k++)
        bad += memcmp(&lf_a[k], &lf_b[k], sizeof(float)) != 0;
    /* the same turns and sums in double */
    for (Py_ssize_t b0 = lo; b0 < hi; b0 += 16)
        for (int side = 1; side <= 2; side++)
            for (Py_ssize_t li = b0; li < hi && li < b0 + 16; li++) {
                double R[9], a[3], m[3];
                for (int k = 0; k < 9; k++)
                    R[k] = (float)rot[9 * v1[li] + k];
                for (int c = 0; c < 3; c++) {
                    a[c] = side == 1 ? of[c * FS + li]
                                     : (neg2[li] != 0.0 ? -of[c * FS + li] : of[(3 + c) * FS + li]);
                    m[c] = of[((side == 1 ? 6 : 9) + c) * FS + li];
                }
                /* P^T: the bond frame's (x, y, z) in voxel 1's frame */
                double pa[3], pm[3];
                if (ax == 0) {
                    for (int c = 0; c < 3; c++) { pa[c] = a[c]; pm[c] = m[c]; }
                } else if (ax == 1) {
                    pa[0] = -a[1]; pa[1] = a[0]; pa[2] = a[2];
                    pm[0] = -m[1]; pm[1] = m[0]; pm[2] = m[2];
                } else {
                    pa[0] = -a[2]; pa[1] = a[1]; pa[2] = a[0];
                    pm[0] = -m[2]; pm[1] = m[1]; pm[2] = m[0];
                }
                Py_ssize_t v = side == 1 ? v1[li] : v2[li];
                for (int c = 0; c < 3; c++) {
                    ref[c * NV + v] += R[3 * c] * pa[0] + R[3 * c + 1] * pa[1] + R[3 * c + 2] * pa[2];
                    ref[(3 + c) * NV + v] += R[3 * c] * pm[0] + R[3 * c + 1] * pm[1] + R[3 * c + 2] * pm[2];
                }
            }
    for (int k = 0; k < 6; k++)
        for (int v = 0; v < NV; v++)
            bad_sums += fabs(lf_a[k * LFS + v] - ref[k * NV + v]) > 1e-5;
    return bad;
}
int main(void)
{
    for (int i = 0; i < NV; i++) {
        URAND_ROT(rot + 9 * i);
    }
    long bad = 0;
    for (int pattern = 0; pattern < 4; pattern++)
        for (int offset = 0; offset < 3; offset++) {
            links(pattern, 5 * offset);
            for (int ax = 0; ax < 3; ax++) {
                bad += check(ax, 0, N);
                bad += check(ax, 3, N - 5);  /* a run's start mid-block, its end mid-block */
                bad += check(ax, 7, 20);
            }
        }
    printf("%ld %ld\n", bad, bad_sums);
    return 0;
}
""")


COROT_SCATTER_HARNESS = _c_harness("softgym_corot.h", r"""
/* softgym_corot_scatter (with AVX-512: blocks of 8 links turned into rows of 4 in
   registers) against the scatter written out per component, link by link: the voxels'
   forces and moments (lanes 0-2 and 4-6 of their rows), and where it stops (a strained
   link) */
enum { NV = 300, N = 203, S = SOFTGYM_FM_STRIDE, FM = SOFTGYM_FM_STRIDE * NV };
static double fm_a[FM] __attribute__((aligned(64))), fm_b[FM] __attribute__((aligned(64)));
static double o[10 * N];
static Py_ssize_t v1[N], v2[N];
static long check(Py_ssize_t strained)
{
    const double max_ext = 0.4;
    for (int k = 0; k < 10 * N; k++)
        o[k] = urand();
    for (int li = 0; li < N; li++)
        o[li] = 0.3 * (urand() + 0.5);  /* |extension| under max_ext */
    if (strained >= 0)
        o[strained] = 0.5;
    urand_both(fm_a, fm_b, FM);
    Py_ssize_t end = softgym_corot_scatter(0, N, N, max_ext, v1, v2, o, fm_a, fm_a + 4);
    Py_ssize_t want = strained >= 0 ? strained : N;
    for (Py_ssize_t li = 0; li < want; li++)
        for (int c = 0; c < 3; c++) {
            fm_b[S * v2[li] + c] += o[(1 + c) * N + li];
            fm_b[S * v1[li] + c] -= o[(1 + c) * N + li];
            fm_b[S * v1[li] + 4 + c] += o[(4 + c) * N + li];
            fm_b[S * v2[li] + 4 + c] += o[(7 + c) * N + li];
        }
    return (end != want) + rows_differ(fm_a, fm_b, NV);
}
int main(void)
{
    long bad = 0;
    for (int pattern = 0; pattern < 3; pattern += 2) {  /* runs along x, any voxels */
        link_pattern(pattern, v1, v2, N, NV);
        bad += check(-1) + check(45) + check(200);
    }
    printf("%ld\n", bad);
    return 0;
}
""")


@pytest.mark.parametrize("level", ["x86-64-v3", "x86-64-v4"])
@pytest.mark.parametrize("model", ["seed", "corotational"])
def test_the_scatters_in_blocks_are_the_scatters_link_by_link_bit_for_bit(model, level, tmp_path):
    # the seed scatter against its own links one by one, the corotational one against
    # the scatter written out per component (and where it stops at a strained link)
    harness = SCATTER_HARNESS if model == "seed" else COROT_SCATTER_HARNESS
    out = _run_harness(level, harness, tmp_path)
    assert out == "0", f"{out} voxel components (or ends) differ"


@pytest.mark.parametrize("level", ["x86-64", "x86-64-v3", "x86-64-v4"])
def test_the_float_push_in_blocks_is_the_push_link_by_link_bit_for_bit(level, tmp_path):
    # the AVX-512 blocks (windows, runs, the guard's fall-back) against the links one by
    # one, bit for bit, and both within float rounding of the turns and sums in double
    differ, off = _run_harness(level, PUSH_HARNESS, tmp_path).split()
    assert differ == "0", f"{differ} voxel components differ between the blocks and the links"
    assert off == "0", f"{off} voxel sums off the double turn by more than 1e-5"


MODES_HARNESS = _c_harness("softgym_seed.h", r"""
/* softgym_seed_modes (branch-free, vectorised, the strain check after the loop) against
   the seed's scalar loop written out (p0 / nom compared, stopping at the first strained
   link): each link's mode, its rows 9, 22 and 23 up to where the loop stops, and that
   link. Links right at the thresholds (quotients within a few units in the last place of
   1.3 and 1.43), strained links, NaN */
enum { N = 203, ROWS = 24 };
static double o[ROWS * N], ref[ROWS * N];
static long long sa_a[N], sa_b[N], homog[N];
static const double SA_W = 0.9999625, SAH_W = 0.99995, ST_IN = 0.05, EX_IN = 1.30;
static const double ST_OUT = 0.055, EX_OUT = 1.43, MAX_EXT = 0.02;
static Py_ssize_t reference(long long *sa_, double *r)
{
    for (Py_ssize_t li = 0; li < N; li++) {
        double p0 = r[li], qw = r[3 * N + li], nom = r[7 * N + li], st = r[9 * N + li];
        double ex = p0 / nom, P0;
        int sa = sa_[li] != 0, changed = 0;
        if (!sa && qw > SA_W && st < ST_IN && ex < EX_IN) {
            sa = 1;
            changed = 1;
        } else if (sa && (!(qw > SAH_W) || st > ST_OUT || ex > EX_OUT)) {
            sa = 0;
            changed = 1;
        }
        sa_[li] = sa;
        r[9 * N + li] = sa ? 1.0 : 0.0;
        r[22 * N + li] = changed ? 1.0 : 0.0;
        r[23 * N + li] = (changed || homog[li]) ? 1.0 : 0.0;
        P0 = sa ? p0 - nom : r[8 * N + li] - nom;
        if (!(fabs(P0) <= MAX_EXT))
            return li;
    }
    return N;
}
static long check(int round)
{
    for (Py_ssize_t li = 0; li < N; li++) {
        double nom = 0.01 * (1.0 + 0.2 * urand());
        double c = rand() % 2 ? EX_IN : EX_OUT;
        int k = rand() % 17 - 8;  /* the quotient within 8 units in the last place of c */
        double p0 = rand() % 4 ? nom * (1.0 + 0.02 * urand()) : c * nom * (1.0 + k * 0x1p-52);
        o[li] = p0;
        o[1 * N + li] = 6e-4 * urand();
        o[2 * N + li] = 6e-4 * urand();
        o[3 * N + li] = 1.0 - 1e-4 * (urand() + 0.5);
        o[7 * N + li] = nom;
        o[8 * N + li] = p0 * (1.0 + 1e-3 * urand());
        /* the transverse ratio as the geometry leaves it */
        o[9 * N + li] = (fabs(o[2 * N + li]) + fabs(o[1 * N + li])) / p0;
        sa_a[li] = sa_b[li] = rand() % 2;
        homog[li] = rand() % 2;
    }
    if (round == 1)
        o[150] = o[7 * N + 150] + 0.05;  /* strained from link 150 on */
    if (round == 2)
        o[7 * N + 60] = NAN;
    memcpy(ref, o, sizeof o);
    Py_ssize_t end = softgym_seed_modes(0, N, N, MAX_EXT, SA_W, SAH_W, ST_IN, EX_IN, ST_OUT,
                                        EX_OUT, sa_a, homog, o);
    Py_ssize_t want = reference(sa_b, ref);
    long bad = end != want;
    for (Py_ssize_t li = 0; li < N; li++) {
        bad += sa_a[li] != sa_b[li];
        for (int r = 9; r < 24; r += r == 9 ? 13 : 1)
            bad += li <= want && memcmp(&o[r * N + li], &ref[r * N + li], sizeof(double)) != 0;
    }
    return bad;
}
int main(void)
{
    long bad = 0;
    for (int round = 0; round < 300; round++)
        bad += check(round % 3);
    printf("%ld\n", bad);
    return 0;
}
""")


GEOM_MODES_HARNESS = _c_harness("softgym_seed.h", r"""
/* softgym_seed_geom_modes (with AVX-512 the modes of the geometry's vector blocks decided in
   its loop, softgym_seed_modes8v, from the values in registers; the peel and the tail by
   the modes loop) against softgym_seed_geom then softgym_seed_modes: where the step stops
   (a strained link), every link's mode, and rows 0-6, 8, 9, 10, 22, 23 (and 7 where kept) of
   every link, over runs, windows and gathers, chunk by chunk from offsets that leave a peel */
enum { NV = 200, N = 203, ROWS = 24 };
static double pos[3 * NV], quat[4 * NV], sc[NV], vr[SOFTGYM_VOXEL_ROWS * NV];
static double rows_a[ROWS * SOFTGYM_CHUNK_STRIDE] __attribute__((aligned(64)));
static double rows_b[ROWS * SOFTGYM_CHUNK_STRIDE] __attribute__((aligned(64)));
static long long sa_a[N], sa_b[N], homog[N];
static Py_ssize_t v1[N], v2[N];
/* links c1..c2 of the chunk from link c0 (c1 > c0: a run that starts mid-chunk, as the y
   and z links do, so the vector loop has a peel) */
static long check(int ax, double max_ext, int keep_len, Py_ssize_t c0, Py_ssize_t c1,
                  Py_ssize_t c2)
{
    const Py_ssize_t n = SOFTGYM_CHUNK_STRIDE;
    for (int k = 0; k < ROWS * SOFTGYM_CHUNK_STRIDE; k++)
        rows_a[k] = rows_b[k] = urand();
    for (Py_ssize_t li = 0; li < N; li++) {
        sa_a[li] = sa_b[li] = rand() % 2;
        homog[li] = rand() % 2;
    }
    double *oa = rows_a - c0, *ob = rows_b - c0;
    softgym_modes_args m = {max_ext, 0.3, 0.2, 0.8, 1.6, 0.9, 2.0, sa_b, homog, keep_len};
    softgym_seed_geom(ax, c1, c2, n, v1, v2, NV, pos, quat, vr, NV, sc, oa, (double *)0,
                      (float *)0);
    Py_ssize_t want = softgym_seed_modes(c1, c2, n, m.max_ext, m.sa_w, m.sah_w, m.st_in,
                                         m.ex_in, m.st_out, m.ex_out, sa_a, homog, oa);
    Py_ssize_t end = softgym_seed_geom_modes(ax, c1, c2, n, v1, v2, NV, pos, quat, vr, NV, sc,
                                             ob, (double *)0, (float *)0, &m);
    long bad = end != want;
    for (Py_ssize_t li = c1; li < c2; li++) {
        bad += sa_a[li] != sa_b[li];
        for (int r = 0; r < ROWS; r++) {
            if ((r == 7 && !keep_len) || (r > 10 && r < 22))
                continue;
            bad += memcmp(&oa[r * n + li], &ob[r * n + li], sizeof(double)) != 0;
        }
    }
    return bad;
}
int main(void)
{
    urand_voxels(NV, pos, quat, sc, vr, NV);
    long bad = 0;
    for (int pattern = 0; pattern < 3; pattern++) {
        for (int li = 0; li < N; li++) {
            if (pattern == 0) {  /* random voxels: gathers */
                v1[li] = rand() % NV;
                v2[li] = (v1[li] + 1 + rand() % (NV - 1)) % NV;
            } else if (pattern == 1) {  /* runs of consecutive voxels */
                v1[li] = li % (NV - 7);
                v2[li] = v1[li] + 7;
            } else {  /* a lattice row's links with gaps: windows of 16 */
                v1[li] = (li + li / 5) % (NV - 1);
                v2[li] = v1[li] + 1;
            }
        }
        for (int ax = 0; ax < 3; ax++)
            for (int keep = 0; keep < 2; keep++) {
                /* no link strained, some (the step stops at the first), offsets with a peel */
                bad += check(ax, 1.0, keep, 0, 0, SOFTGYM_CHUNK_LINKS);
                bad += check(ax, 0.03, keep, 64, 64, 64 + SOFTGYM_CHUNK_LINKS);
                bad += check(ax, 1.0, keep, 128, 131, 128 + 61);
                bad += check(ax, 0.03, keep, 128, 133, 128 + 63);
                /* a run too short for the peel: its one vector block starts mid-line */
                bad += check(ax, 1.0, keep, 128, 131, 141);
            }
    }
    printf("%ld\n", bad);
    return 0;
}
""")


@pytest.mark.parametrize("level", ["x86-64", "x86-64-v3", "x86-64-v4"])
@pytest.mark.parametrize("harness", ["modes", "geometry_then_modes"])
def test_the_modes_pass_decides_as_the_seeds_scalar_loop(harness, level, tmp_path):
    # the modes pass against the seed's loop; the geometry with its modes (AVX-512: decided
    # in the geometry's loop) against the geometry then the modes pass
    text = MODES_HARNESS if harness == "modes" else GEOM_MODES_HARNESS
    out = _run_harness(level, text, tmp_path)
    assert out == "0", f"{out} modes, rows or ends differ"

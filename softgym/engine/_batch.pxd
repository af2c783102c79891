# The contract every kernel module shares: one struct of raw pointers into the
# flat structure-of-arrays state of a whole batch, the status codes the nogil
# kernels return, and the scratch layout. Arrays are C-contiguous float64
# unless said otherwise; "(n, 3)" means n rows of 3 stored row-major. Units
# are SI. Types and two inline accessors only: no module behind this file.

from softgym.engine._typedefs cimport float64_t, intp_t, step_t, int32, flag_t, lane_flag_t

# Status codes returned by the nogil helpers (errors cross nogil as codes).
cdef enum:
    STATUS_OK = 0
    STATUS_STRAIN = 1       # a link's engineering strain exceeded max_strain (or was NaN)
    STATUS_NONFINITE = 2    # a voxel's position became non-finite or ran away
    STATUS_MEMORY = 3       # the self-collision candidate list could not be allocated


cdef struct Batch:
    # ---- global settings -------------------------------------------------
    intp_t n_robots          # robots in the batch
    float64_t L              # lattice dimension, nominal voxel edge (m)
    float64_t gravity        # gravitational acceleration along +z (m/s^2; -9.81 = down)
    float64_t init_time      # settling time: no sinusoidal actuation before it; IniCM after it (s)
    float64_t min_scale      # smallest actuated edge, as a fraction of L
    float64_t max_strain     # divergence threshold on |link engineering strain|
    float64_t trace_interval # seconds between centre-of-mass samples
    int32 self_collision     # 1: contact between voxels more than the exclusion hops apart
    int32 actuation_mode     # 0: seed (contraction only, hold out-of-bounds); 1: symmetric
    int32 model              # 0: seed (the seed engine's step, see _seed.pyx); 1: corotational
    float64_t bond_zeta      # the seed's BondDampingZ (model 0's finite-difference link damping)
    int32 link_f32           # model 0's frames and forces passes in single precision (1) or double (0)
    intp_t trace_capacity    # samples allocated per robot in trace_t / trace_cm
    float64_t fluid_drag     # 1/2 rho C_d of a surrounding fluid (kg/m^3): quadratic drag on
                             # each exposed face moving into it; 0: no fluid

    # ---- per robot ----------------------------------------------------------
    intp_t* vox_start        # (n_robots + 1,) robot r owns voxels [vox_start[r], vox_start[r+1])
    intp_t* link_start       # (n_robots + 1,) robot r owns links [link_start[r], link_start[r+1])
    intp_t* link_axis_count  # (n_robots, 3) its links along x, then y, then z (sorted by axis)
    float64_t* dt            # (n_robots,) time step (s)
    step_t* steps            # (n_robots,) steps taken; the robot's clock is steps * dt
    float64_t* temp_amp      # (n_robots,) amplitude dT of the temperature sinusoid (degC)
    float64_t* period        # (n_robots,) period of the temperature sinusoid (s)
    flag_t* use_temp         # (n_robots,) 1: per-voxel temperatures replace the sinusoid
    flag_t* floor            # (n_robots,) 1: floor plane z = 0 with penalty contact and friction
    intp_t* box_start        # (n_robots + 1,) robot r's obstacles are boxes [box_start[r], box_start[r+1])
    float64_t* boxes         # (n_boxes, 6) static boxes x0, y0, z0, x1, y1, z1 (m)
    flag_t* diverged         # (n_robots,) 1: frozen after divergence
    float64_t* diverged_time # (n_robots,) time of divergence (s)
    int32* diverged_code     # (n_robots,) STATUS_* code of the divergence
    flag_t* init_done        # (n_robots,) 1: cm_init recorded
    float64_t* cm_init       # (n_robots, 3) CM at the first step with t > init_time (m)
    float64_t* mass_total    # (n_robots,) total mass (kg)
    intp_t* trace_n          # (n_robots,) samples recorded
    float64_t* trace_t       # (n_robots, trace_capacity) sample times (s)
    float64_t* trace_cm      # (n_robots, trace_capacity, 3) sampled CM (m)
    intp_t* body_end         # (n_robots,) robot r's own voxels are [vox_start[r], body_end[r]); the
                             # rest of its range are passive objects (CTE 0, outside its CM)
    float64_t* aux_init      # (n_robots, N_AUX) robot_aux when cm_init was recorded
    float64_t* trace_aux     # (n_robots, trace_capacity, N_AUX) robot_aux at each CM sample

    # ---- per voxel ------------------------------------------------------------
    float64_t* pos           # (n_voxels, 3) centre position (m)
    float64_t* vel           # (n_voxels, 3) velocity (m/s)
    float64_t* quat          # (n_voxels, 4) orientation, unit quaternion (w, x, y, z)
    float64_t* angvel        # (n_voxels, 3) angular velocity, world frame (rad/s)
    float64_t* rot           # (n_voxels, 9) rotation matrix of quat, row-major (derived)
    float64_t* force         # (n_voxels, SOFTGYM_FM_STRIDE) scratch, one 64-byte row a voxel:
                             #   accumulated force (N) in columns 0-2, moment (N m) in 4-6;
                             #   columns 3 and 7 pad it (the vector scatters add whole
                             #   rows) and are never read; voxel i's force at
                             #   force[SOFTGYM_FM_STRIDE * i]
    float64_t* moment        # force + 4: voxel i's moment at moment[SOFTGYM_FM_STRIDE * i]
    float* link_f            # NULL, or (model 0 with link_f32, during advance) the thread's
                             #   float rows of the link forces in place of force and
                             #   moment: 6 rows (force x, y, z, moment x, y, z), row k of
                             #   voxel i at link_f[k * link_fs + i], i among the robot's
                             #   voxels (the links' push and the contacts add into them,
                             #   the voxel update widens them to doubles and zeroes them)
    intp_t link_fs           # their row stride
    float64_t* vox_out       # the voxel update's scratch, SOFTGYM_VOXEL_ROWS rows: row k of
                             #   voxel i at vox_out[k * vox_stride + i], i among the robot's
                             #   voxels (include/softgym_simd.h)
    intp_t vox_stride        # its row stride (the most voxels of one robot)
    float64_t* state_rows    # NULL, or b.vox_out while a step loop of an AVX-512 build
                             #   (SOFTGYM_STATE_ROWS) keeps the voxels' state in its rows
                             #   (include/softgym_simd.h): pos, quat, vel and angvel are
                             #   stale then; voxel_pos / voxel_quat read either
    float64_t* ext_force     # (n_voxels, 3) constant external force (N)
    float64_t* mass          # (n_voxels,) rho L^3 (kg)
    float64_t* inv_mass      # (n_voxels,) 1 / mass
    float64_t* inv_inertia   # (n_voxels,) 1 / (mass L^2 / 6)
    float64_t* scale         # (n_voxels,) current actuated edge length (m)
    float64_t* cte           # (n_voxels,) coefficient of thermal expansion (1/degC)
    float64_t* cos_phase     # (n_voxels,) cos of the voxel's phase offset
    float64_t* sin_phase     # (n_voxels,) sin of the voxel's phase offset
    float64_t* temp          # (n_voxels,) temperature used when use_temp (degC)
    float64_t* k_floor       # (n_voxels,) floor penalty stiffness 2 E L (N/m)
    float64_t* c_floor       # (n_voxels,) floor normal damping zeta_c 2 sqrt(m E L) (N s/m)
    float64_t* c_global      # (n_voxels,) global damping zeta_g 2 sqrt(m E L) (N s/m)
    float64_t* rot_damp      # (n_voxels,) per-step angular momentum factor of global damping
    float64_t* mu_s          # (n_voxels,) static friction coefficient
    float64_t* mu_k          # (n_voxels,) kinetic friction coefficient
    flag_t* fixed            # (n_voxels,) 1: all six degrees of freedom fixed
    flag_t* surface          # (n_voxels,) 1: misses a face bond (takes part in self-collision)
    intp_t* excl_start       # (n_voxels + 1,) CSR rows of voxels that never collide with voxel i
    intp_t* excl_idx         # (excl_start[-1],) their indices, sorted within each row
    flag_t* faces            # (n_voxels,) exposed faces in the voxel's frame: bit 2a the -a face,
                             # bit 2a + 1 the +a face (a = 0, 1, 2 for x, y, z); for fluid drag

    # ---- per link (beam between face neighbours v1 -> v2 along +axis) ------
    intp_t n_links           # links in the batch
    intp_t link_rows         # row stride (elements) of c_seed, k_seed32 and link_last: n_links
                             #   or more (row_stride in _core: rows apart in the cache)
    float64_t* link_out      # scratch of the corotational link kernel (it names its rows): row k
                             #   of link li at link_out[k * link_stride + li], li among the robot's
                             #   links (the seed model's is chunk_link)
    intp_t link_stride       # its row stride (the most links of one robot)
    float64_t* chunk_out     # scratch of the seed model's forces pass: SOFTGYM_CHUNK_ROWS rows,
                             #   SOFTGYM_CHUNK_STRIDE apart, for one chunk of links from its
                             #   first (include/softgym_seed.h, _seed.links_seed)
    float64_t* chunk_link    # the seed model's link scratch for one chunk of links: N_LINK_OUT
                             #   rows, SOFTGYM_CHUNK_STRIDE apart, indexed by link from the chunk's
                             #   first (_seed.links_seed; per thread)
    float* chunk_f32         # scratch of the seed model's single-precision frames and forces:
                             #   SOFTGYM_CHUNK_FROWS float rows, SOFTGYM_CHUNK_FSTRIDE apart, for one
                             #   chunk of links (the forces' from row SOFTGYM_CHUNK_FOUT, voxel
                             #   1's rotation rounded from row SOFTGYM_CHUNK_FR)
    intp_t* v1               # (n_links,) voxel on the negative side
    intp_t* v2               # (n_links,) voxel on the positive side
    int32* axis              # (n_links,) 0, 1, 2 for x, y, z
    float64_t* k_axial       # (n_links,) E L (N/m)
    float64_t* k_torsion     # (n_links,) E L^3 / (12 (1 + nu)) (N m/rad)
    float64_t* k_bend        # (n_links,) E L^3 / 6 (N m/rad), the b3 of the seed
    float64_t* c_axial       # (n_links,) axial damping (N s/m)
    float64_t* c_torsion     # (n_links,) torsional damping (N m s/rad)
    float64_t* c_bend        # (n_links,) bending damping (N m s/rad)
    # model 0 (seed) only:
    float64_t* c_seed        # (8, n_links), rows link_rows apart: 2 sqrt(k m) damping constants
                             #   of voxel 1 then voxel 2: a1 M, b2 FM, a2 I, b3 I
                             #   (FM = M L / 2, I = M L^2 / 6)
    lane_flag_t* homog       # (n_links,) int64, 1: voxel 2 gets -F1 (one material, or two with equal
                             #   damping constants a M, b2 FM: layout._robot_entry)
    float* k_seed32          # (11, n_links), rows link_rows apart, float32: k_axial, k_torsion,
                             #   k_bend, c_seed's 8 rows (link_f32 only; NULL otherwise)
    lane_flag_t* link_sa     # (n_links,) int64, 1: small-angle mode (state; int8 in states:
                             #   simulation._STATE_DTYPE)
    intp_t* seed_rank        # (n_voxels,) the voxel's index in the seed engine's order
    float64_t* col_ref       # (n_voxels, 4) position and size at the last candidate rebuild (state)
    float64_t* col_acc       # (n_robots,) the seed's displacement since that rebuild, in L (state)
    float64_t* col_vmax      # (n_robots,) fastest voxel speed after the last step (state)
    intp_t* obs_start        # (n_robots + 1,) model 0: robot r's obstacle voxels [obs_start[r], obs_start[r+1])
    float64_t* obs           # (n_obs, 4) fixed obstacle voxel centre (m) and its 2 E L (N/m)
    intp_t* obs_rank         # (n_obs,) its index in the seed engine's voxel order
    float64_t* link_last     # (9, n_links), rows link_rows apart: last Pos2, Angle1, Angle2 in
                             #   the bond frame (state; Simulation.get_state/set_state show it
                             #   as (n_links, 9)); NULL with link_f32
    float* link_last32       # the same in float32 with link_f32 (NULL otherwise)


# What robot_aux reports (columns of aux_init / trace_aux).
cdef enum:
    N_AUX = 10               # objects' CM (3, m; 0 without objects), heading sum (2: the mass-
                             # weighted x axes of the robot's voxels, x and y), bounding box of the
                             # robot's voxel centres (5, m: x lo, x hi, y lo, y hi, z hi)


# Rows of the per-thread scratch the link and voxel kernels share
# (Batch.link_out; Batch.vox_out has SOFTGYM_VOXEL_ROWS; allocated by _core.advance).
cdef enum:
    N_LINK_OUT = 25          # rows of the per-link scratch (see _corotational, _seed)


cdef extern from "softgym_simd.h":
    # the row of Batch.force (doubles a voxel: its force, then its moment)
    enum: SOFTGYM_FM_STRIDE
    # rows of the per-voxel scratch, Batch.vox_out (the voxel update's quaternions; the
    # seed step's voxel rows)
    enum: SOFTGYM_VOXEL_ROWS
    # the rows of the step loops' quaternions and positions there
    enum: SOFTGYM_ROW_QUAT
    enum: SOFTGYM_ROW_POS


cdef inline float64_t voxel_pos(const Batch* b, intp_t i, int k) noexcept nogil:
    # component k of voxel i's position, from the records or the state rows
    if b.state_rows != NULL:
        return b.state_rows[(SOFTGYM_ROW_POS + k) * b.vox_stride + i]
    return b.pos[3 * i + k]


cdef inline void voxel_quat(const Batch* b, intp_t i, float64_t* q) noexcept nogil:
    # q[0:4] = voxel i's quaternion (w, x, y, z), from the records or the state rows
    cdef int k
    if b.state_rows != NULL:
        for k in range(4):
            q[k] = b.state_rows[(SOFTGYM_ROW_QUAT + k) * b.vox_stride + i]
    else:
        for k in range(4):
            q[k] = b.quat[4 * i + k]


cdef extern from "softgym_restrict.h":
    # restrict-qualified pointers: a vectorised kernel's inputs and outputs
    # never alias, which lets the compiler vectorise it (gathers + SIMD); the
    # qualifier is SOFTGYM_RESTRICT, spelt for each compiler in the header
    ctypedef double* f64_rp "double * SOFTGYM_RESTRICT"
    ctypedef const double* cf64_rp "const double * SOFTGYM_RESTRICT"
    ctypedef const Py_ssize_t* cintp_rp "const Py_ssize_t * SOFTGYM_RESTRICT"

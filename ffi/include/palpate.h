/*
 * palpate.h: the C interface of Palpate, a real-time soft-tissue kernel for
 * haptic surgery simulators (the static library libpalpate_ffi.a).
 *
 * Generated from the Rust sources in ffi/src by tools/ffi-header (cbindgen,
 * ffi/cbindgen.toml): edit the doc comments there, not this file.
 *
 * What it does. A haptic device controller loads a table built offline by
 * `palpate tables build` (in flash or RAM), creates a haptic loop over it,
 * and calls palpate_*_loop_tick at the haptic rate (1 kHz or more) with the
 * tool positions; each tick gives the force to render and its status. Three
 * loops: the pre-computed model (quasi-static, linear, solved every tick),
 * the tensor-mass model (dynamic, cuttable, stepped by
 * palpate_*_loop_physics_update every few ticks) and the hybrid of the two.
 * palpate_precomputed_solve is the scripted solve (given contacts, no
 * detection) that `palpate precomputed replay` runs.
 *
 * Rules every function follows:
 * - It returns a palpate_status: PALPATE_STATUS_OK (0), or why it did
 *   nothing. palpate_status_message gives a short text; a function that
 *   takes `palpate_error *error` (may be NULL) records the details there,
 *   and palpate_error_message formats them (the kernel's own words: which
 *   contact, vertex, section or buffer).
 * - A NULL pointer where one is required gives PALPATE_STATUS_NULL_POINTER,
 *   a misaligned one PALPATE_STATUS_MISALIGNED. Array lengths are element
 *   counts, checked against the table.
 * - No allocation and no global state: every object lives in memory you
 *   give. Handles (palpate_table, palpate_*_loop, palpate_error) are
 *   fixed-size structs: declare them (static storage, or zero-initialized),
 *   pass their address, never copy them. The dynamic and hybrid loops also
 *   take one memory block of palpate_*_memory_size bytes, aligned to
 *   PALPATE_MEMORY_ALIGN. A handle whose creation failed is refused by
 *   every function (PALPATE_STATUS_NOT_INITIALIZED).
 * - Lifetimes: a table's bytes outlive its handle and everything created
 *   from it, unchanged; a loop's tables and memory block outlive the loop.
 * - Not thread-safe: use a handle from one task at a time.
 * - Nothing panics or unwinds into C: every failure is a status.
 * - Scalars are float (f32): build tables with `--precision f32`. Units:
 *   m, N, s, kg, J (names end with the unit).
 *
 * A minimal pre-computed haptic loop:
 *
 *     extern const uint8_t table_bytes[];  // 16-byte aligned, in flash
 *     extern const size_t table_len;
 *     static palpate_table table;
 *     static palpate_precomputed_loop haptic;
 *
 *     int haptic_init(void) {
 *         palpate_loop_config config = palpate_loop_config_default();
 *         if (palpate_abi_version() != PALPATE_ABI_VERSION) return -1;
 *         if (palpate_precomputed_table_load(&table, table_bytes, table_len, NULL)) return -1;
 *         return palpate_precomputed_loop_create(&haptic, &table, &config, NULL) ? -1 : 0;
 *     }
 *
 *     void haptic_tick(const float tip_m[3], float force_n[3]) {  // every 1 ms
 *         palpate_tool tool = {{tip_m[0], tip_m[1], tip_m[2]}, PALPATE_TOOL_ACTION_TOUCH, {0}};
 *         palpate_force out;
 *         palpate_precomputed_loop_tick(&haptic, &tool, 1, &out);
 *         for (int i = 0; i < 3; i++) force_n[i] = out.force_n[i];
 *         // out.status: a latched fault renders zero until palpate_precomputed_loop_reset.
 *     }
 */

#ifndef PALPATE_H
#define PALPATE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
/* Handles are larger on 64-bit targets (the host) than on 32-bit ones
   (Cortex-M): their sizes below depend on this. */
#if UINTPTR_MAX > 0xFFFFFFFFu
#define PALPATE_POINTER_64 1
#endif

/*
 Version of this C ABI: raised whenever a function, a struct's layout, a
 handle's size or a code's meaning changes. Compare
 `palpate_abi_version()` with it at start-up to catch a header and a
 library of different versions.
 */
#define PALPATE_ABI_VERSION 6

/*
 The table format version this library reads (`palpate tables build`
 writes it; any other version is refused with
 `PALPATE_STATUS_TABLE_UNSUPPORTED_VERSION`).
 */
#define PALPATE_TABLE_FORMAT_VERSION 6

/*
 Tool points of a haptic loop, at most (a probe tip, a grasper's two
 jaws, a spare): a loop is created with 1 to this many.
 */
#define PALPATE_TOOL_POINTS 4

/*
 Simultaneous contacts, at most: of a scripted solve and of a haptic
 loop (a fifth tool point in contact is refused and counted).
 */
#define PALPATE_MAX_CONTACTS 4

/*
 Alignment, bytes, of the memory block given to
 `palpate_dynamic_loop_create` and `palpate_hybrid_loop_create`.
 */
#define PALPATE_MEMORY_ALIGN 8

/*
 Words of a `palpate_error`.
 */
#define PALPATE_ERROR_WORDS 8

#if defined(PALPATE_POINTER_64)
/*
 Words of a `palpate_table` on 64-bit targets (the host).
 */
#define PALPATE_TABLE_WORDS 87
#endif

#if !defined(PALPATE_POINTER_64)
/*
 Words of a `palpate_table` on 32-bit targets (Cortex-M).
 */
#define PALPATE_TABLE_WORDS 62
#endif

/*
 Words of a `palpate_solution_state`.
 */
#define PALPATE_SOLUTION_WORDS 32

#if defined(PALPATE_POINTER_64)
/*
 Words of a `palpate_precomputed_loop` on 64-bit targets (the host).
 */
#define PALPATE_PRECOMPUTED_LOOP_WORDS 402
#endif

#if !defined(PALPATE_POINTER_64)
/*
 Words of a `palpate_precomputed_loop` on 32-bit targets (Cortex-M).
 */
#define PALPATE_PRECOMPUTED_LOOP_WORDS 356
#endif

#if defined(PALPATE_POINTER_64)
/*
 Words of a `palpate_dynamic_loop` on 64-bit targets (the host).
 */
#define PALPATE_DYNAMIC_LOOP_WORDS 476
#endif

#if !defined(PALPATE_POINTER_64)
/*
 Words of a `palpate_dynamic_loop` on 32-bit targets (Cortex-M).
 */
#define PALPATE_DYNAMIC_LOOP_WORDS 380
#endif

#if defined(PALPATE_POINTER_64)
/*
 Words of a `palpate_hybrid_loop` on 64-bit targets (the host).
 */
#define PALPATE_HYBRID_LOOP_WORDS 670
#endif

#if !defined(PALPATE_POINTER_64)
/*
 Words of a `palpate_hybrid_loop` on 32-bit targets (Cortex-M).
 */
#define PALPATE_HYBRID_LOOP_WORDS 523
#endif

/*
 What a function did: `PALPATE_STATUS_OK`, or why it did nothing (a function
 that fails leaves its outputs and handles as they were, except a
 creation's handle, which is marked not initialized).
 */
enum palpate_status
#if defined(__cplusplus) || __STDC_VERSION__ >= 202311L
  : uint32_t
#endif // defined(__cplusplus) || __STDC_VERSION__ >= 202311L
 {
  /*
   Success.
   */
  PALPATE_STATUS_OK = 0,
  /*
   A required pointer is null.
   */
  PALPATE_STATUS_NULL_POINTER = 1,
  /*
   A pointer is not aligned for its type (a handle: 8 bytes; `float` and
   `uint32_t` arrays: 4; the memory block: `PALPATE_MEMORY_ALIGN`).
   */
  PALPATE_STATUS_MISALIGNED = 2,
  /*
   A handle that no successful call created (never created, or its
   creation failed).
   */
  PALPATE_STATUS_NOT_INITIALIZED = 3,
  /*
   A table handle of another kind than the function takes (a
   tensor-mass table where a pre-computed one is needed).
   */
  PALPATE_STATUS_WRONG_TABLE = 4,
  /*
   An argument out of range: an enum value not in its list, a count
   above its capacity, a tool count other than the loop's.
   */
  PALPATE_STATUS_BAD_ARGUMENT = 5,
  /*
   The memory block is smaller than `palpate_*_memory_size` says.
   */
  PALPATE_STATUS_MEMORY_TOO_SMALL = 6,
  /*
   Fewer bytes than a header and a checksum.
   */
  PALPATE_STATUS_TABLE_TOO_SHORT = 100,
  /*
   Not a Palpate table (the first 8 bytes are not `PALPTBL\0`).
   */
  PALPATE_STATUS_TABLE_BAD_MAGIC = 101,
  /*
   A table format version this library does not read
   (`PALPATE_TABLE_FORMAT_VERSION`).
   */
  PALPATE_STATUS_TABLE_UNSUPPORTED_VERSION = 102,
  /*
   The length given differs from the header's (truncated or padded).
   */
  PALPATE_STATUS_TABLE_LENGTH_MISMATCH = 103,
  /*
   The CRC-32 trailer does not match the contents: a corrupt table.
   */
  PALPATE_STATUS_TABLE_CHECKSUM_MISMATCH = 104,
  /*
   The table stores f64; this library reads f32 tables
   (`palpate tables build --precision f32`).
   */
  PALPATE_STATUS_TABLE_SCALAR_MISMATCH = 105,
  /*
   The table is of another kind than the function loads.
   */
  PALPATE_STATUS_TABLE_WRONG_KIND = 106,
  /*
   The header's counts contradict each other.
   */
  PALPATE_STATUS_TABLE_INCONSISTENT_HEADER = 107,
  /*
   The header's material is out of range.
   */
  PALPATE_STATUS_TABLE_BAD_MATERIAL = 108,
  /*
   A section kind this version does not know.
   */
  PALPATE_STATUS_TABLE_UNKNOWN_SECTION = 109,
  /*
   A section occurs twice.
   */
  PALPATE_STATUS_TABLE_DUPLICATE_SECTION = 110,
  /*
   A required section is missing.
   */
  PALPATE_STATUS_TABLE_MISSING_SECTION = 111,
  /*
   A section has the wrong size.
   */
  PALPATE_STATUS_TABLE_SECTION_SIZE = 112,
  /*
   A section lies outside the table.
   */
  PALPATE_STATUS_TABLE_SECTION_BOUNDS = 113,
  /*
   A section is misaligned in memory: the table's bytes must start on
   a 16-byte boundary.
   */
  PALPATE_STATUS_TABLE_MISALIGNED = 114,
  /*
   The vertex maps disagree.
   */
  PALPATE_STATUS_TABLE_BAD_VERTEX_MAP = 115,
  /*
   A surface triangle references a vertex out of range.
   */
  PALPATE_STATUS_TABLE_BAD_TRIANGLE = 116,
  /*
   A non-finite value.
   */
  PALPATE_STATUS_TABLE_NON_FINITE = 117,
  /*
   The edge list is broken.
   */
  PALPATE_STATUS_TABLE_BAD_EDGES = 118,
  /*
   A tet's references or rest volume are invalid.
   */
  PALPATE_STATUS_TABLE_BAD_TET = 119,
  /*
   A mesh triangle is invalid or out of order.
   */
  PALPATE_STATUS_TABLE_BAD_MESH_TRIANGLE = 120,
  /*
   A tet's mesh-triangle reference is invalid.
   */
  PALPATE_STATUS_TABLE_BAD_TET_TRIANGLE = 121,
  /*
   The collision grid is malformed.
   */
  PALPATE_STATUS_TABLE_BAD_SURFACE_GRID = 122,
  /*
   A surface triangle's stored plane is wrong.
   */
  PALPATE_STATUS_TABLE_BAD_SURFACE_PLANE = 123,
  /*
   A vertex's surface-triangle list is malformed.
   */
  PALPATE_STATUS_TABLE_BAD_VERTEX_TRIANGLES = 124,
  /*
   A lumped mass or vertex tensor is invalid.
   */
  PALPATE_STATUS_TABLE_BAD_VERTEX_DATA = 125,
  /*
   A connection node of an interface table is invalid.
   */
  PALPATE_STATUS_TABLE_BAD_CONNECTION = 126,
  /*
   A tet's Lamé coefficients are out of range.
   */
  PALPATE_STATUS_TABLE_BAD_TET_MATERIAL = 127,
  /*
   A diagonal compliance block is not symmetric positive definite.
   */
  PALPATE_STATUS_TABLE_NOT_POSITIVE_DEFINITE = 128,
  /*
   Compressed table: the compliance-encoding record is malformed (`LoadError::BadCompressionRecord`).
   */
  PALPATE_STATUS_TABLE_BAD_COMPRESSION_RECORD = 129,
  /*
   Compressed table: unknown block encoding (`LoadError::UnknownEncoding`).
   */
  PALPATE_STATUS_TABLE_UNKNOWN_ENCODING = 130,
  /*
   Table section not used by its compliance encoding (`LoadError::UnexpectedSection`).
   */
  PALPATE_STATUS_TABLE_UNEXPECTED_SECTION = 131,
  /*
   Compressed table: a column scale is not finite and > 0, or too large for the codes
   (`LoadError::BadScale`).
   */
  PALPATE_STATUS_TABLE_BAD_SCALE = 132,
  /*
   Compressed table: a fixed-point code is -32768 (`LoadError::BadCode`).
   */
  PALPATE_STATUS_TABLE_BAD_CODE = 133,
  /*
   Compressed table: kept-block bitmap inconsistent (`LoadError::BadKeptBlocks`).
   */
  PALPATE_STATUS_TABLE_BAD_KEPT_BLOCKS = 134,
  /*
   Compressed table: a diagonal compliance block was dropped (`LoadError::DroppedDiagonal`).
   */
  PALPATE_STATUS_TABLE_DROPPED_DIAGONAL = 135,
  /*
   A tet's `tet-lanes` entry differs from its rest shape and material
   (`LoadError::BadTetLanes`).
   */
  PALPATE_STATUS_TABLE_BAD_TET_LANES = 136,
  /*
   A grid cell's candidate triangle list is not the triangles the grid
   files there (`LoadError::BadCellTriangles`).
   */
  PALPATE_STATUS_TABLE_BAD_CELL_TRIANGLES = 137,
  /*
   Hierarchical table: a hierarchy section is inconsistent
   (`LoadError::BadHierarchy`).
   */
  PALPATE_STATUS_TABLE_BAD_HIERARCHY = 138,
  /*
   More contacts than `PALPATE_MAX_CONTACTS`.
   */
  PALPATE_STATUS_CONTACT_TOO_MANY = 200,
  /*
   A vertex index beyond the mesh.
   */
  PALPATE_STATUS_CONTACT_VERTEX_OUT_OF_RANGE = 201,
  /*
   A vertex contact on a fixed vertex.
   */
  PALPATE_STATUS_CONTACT_FIXED_VERTEX = 202,
  /*
   A vertex contact on a vertex that is not on the boundary surface.
   */
  PALPATE_STATUS_CONTACT_NOT_ON_SURFACE = 203,
  /*
   A triangle contact names a vertex twice.
   */
  PALPATE_STATUS_CONTACT_REPEATED_VERTEX = 204,
  /*
   A triangle contact's vertices are not a triangle of the surface.
   */
  PALPATE_STATUS_CONTACT_NOT_SURFACE_TRIANGLE = 205,
  /*
   Barycentric weights outside `[0, 1]` or not summing to 1.
   */
  PALPATE_STATUS_CONTACT_BAD_WEIGHTS = 206,
  /*
   A non-finite displacement or weight.
   */
  PALPATE_STATUS_CONTACT_NON_FINITE_INPUT = 207,
  /*
   Two vertex contacts on one vertex.
   */
  PALPATE_STATUS_CONTACT_DUPLICATE = 208,
  /*
   The contact system is singular or ill-conditioned.
   */
  PALPATE_STATUS_CONTACT_ILL_CONDITIONED = 209,
  /*
   The solve produced a non-finite force.
   */
  PALPATE_STATUS_CONTACT_NON_FINITE_RESULT = 210,
  /*
   A displacement buffer does not hold one entry per vertex.
   */
  PALPATE_STATUS_DISPLACEMENT_BUFFER = 211,
  /*
   Tool radius or haptic period not finite and positive.
   */
  PALPATE_STATUS_LOOP_BAD_CONFIG = 300,
  /*
   Safety limits (force, slew) not finite and positive.
   */
  PALPATE_STATUS_LOOP_BAD_LIMITS = 301,
  /*
   A state buffer has the wrong length.
   */
  PALPATE_STATUS_STATE_BUFFER_LENGTH = 400,
  /*
   A physics parameter (damping, gravity, bounds, penalty) out of range.
   */
  PALPATE_STATUS_STATE_BAD_PARAMETER = 401,
  /*
   The split St Venant-Kirchhoff form without its buffers.
   */
  PALPATE_STATUS_STATE_NO_TERM_BUFFERS = 402,
  /*
   A surface buffer has the wrong length.
   */
  PALPATE_STATUS_SURFACE_BUFFER_LENGTH = 410,
  /*
   The force scratch buffer has the wrong length.
   */
  PALPATE_STATUS_FORCE_BUFFER_LENGTH = 411,
  /*
   Physics step, sub-steps, removal capacities or cut force out of
   range.
   */
  PALPATE_STATUS_BAD_PHYSICS = 412,
  /*
   The model diverged: a non-finite state (a latched fault: reset).
   */
  PALPATE_STATUS_FAULT_NON_FINITE = 420,
  /*
   The model diverged: a displacement beyond the bound (reset).
   */
  PALPATE_STATUS_FAULT_DISPLACEMENT_BOUND = 421,
  /*
   The model diverged: kinetic energy beyond the bound (reset).
   */
  PALPATE_STATUS_FAULT_KINETIC_ENERGY_BOUND = 422,
  /*
   The physics step is not finite and positive.
   */
  PALPATE_STATUS_STEP_BAD_TIME_STEP = 423,
  /*
   RK4 without its scratch buffers.
   */
  PALPATE_STATUS_STEP_NO_RK4_SCRATCH = 424,
  /*
   The deformed surface has a non-finite vertex (reset).
   */
  PALPATE_STATUS_SURFACE_NON_FINITE = 425,
  /*
   A contact's imposed displacement is not finite (reset).
   */
  PALPATE_STATUS_CONTACT_NON_FINITE_DISPLACEMENT = 426,
  /*
   A coupling buffer has the wrong length.
   */
  PALPATE_STATUS_HYBRID_BUFFER_LENGTH = 500,
  /*
   The three tables do not belong together (another build, mesh,
   partition or material).
   */
  PALPATE_STATUS_HYBRID_MISMATCH = 501,
};
#ifndef __cplusplus
#if __STDC_VERSION__ >= 202311L
typedef enum palpate_status palpate_status;
#else
typedef uint32_t palpate_status;
#endif // __STDC_VERSION__ >= 202311L
#endif // __cplusplus

/*
 What a table is for (the kind in its header).
 */
enum palpate_table_kind
#if defined(__cplusplus) || __STDC_VERSION__ >= 202311L
  : uint32_t
#endif // defined(__cplusplus) || __STDC_VERSION__ >= 202311L
 {
  /*
   The pre-computed model's compliance (RR-3510 §4).
   */
  PALPATE_TABLE_KIND_PRECOMPUTED = 1,
  /*
   The tensor-mass model's stiffness and masses (RR-3510 §5).
   */
  PALPATE_TABLE_KIND_TENSOR_MASS = 2,
  /*
   The hybrid's interface, condensing its pre-computed region (RR-3510 §6.2).
   */
  PALPATE_TABLE_KIND_INTERFACE = 3,
};
#ifndef __cplusplus
#if __STDC_VERSION__ >= 202311L
typedef enum palpate_table_kind palpate_table_kind;
#else
typedef uint32_t palpate_table_kind;
#endif // __STDC_VERSION__ >= 202311L
#endif // __cplusplus

/*
 The supervisor's verdict on a tick's force.
 */
enum palpate_output_status
#if defined(__cplusplus) || __STDC_VERSION__ >= 202311L
  : uint32_t
#endif // defined(__cplusplus) || __STDC_VERSION__ >= 202311L
 {
  /*
   The force is the model's.
   */
  PALPATE_OUTPUT_STATUS_OK = 0,
  /*
   The force was reduced by the magnitude clamp or the slew limit.
   */
  PALPATE_OUTPUT_STATUS_CLAMPED = 1,
  /*
   Latched fault, zero force until reset: a non-finite tool position.
   */
  PALPATE_OUTPUT_STATUS_FAULT_NON_FINITE_INPUT = 2,
  /*
   Latched fault, zero force until reset: a non-finite model force.
   */
  PALPATE_OUTPUT_STATUS_FAULT_NON_FINITE_FORCE = 3,
  /*
   Latched fault, zero force until reset: the model refused the
   contact set or diverged.
   */
  PALPATE_OUTPUT_STATUS_FAULT_MODEL = 4,
  /*
   Not latched: a tool point's centre is inside the body with no
   contact (it got deeper than the contact test looks without crossing
   the surface where the test saw it: a first position inside, a jump,
   a contact let go inside). It adds no force: the force is the other
   contacts', slew-limited (with none, it ramps to zero).
   */
  PALPATE_OUTPUT_STATUS_TOOL_INSIDE = 5,
};
#ifndef __cplusplus
#if __STDC_VERSION__ >= 202311L
typedef enum palpate_output_status palpate_output_status;
#else
typedef uint32_t palpate_output_status;
#endif // __STDC_VERSION__ >= 202311L
#endif // __cplusplus

/*
 Where a scripted contact acts (`palpate_contact::kind`).
 */
enum palpate_contact_kind
#if defined(__cplusplus) || __STDC_VERSION__ >= 202311L
  : uint32_t
#endif // defined(__cplusplus) || __STDC_VERSION__ >= 202311L
 {
  /*
   A touchable vertex: `vertices[0]`.
   */
  PALPATE_CONTACT_KIND_VERTEX = 0,
  /*
   A point of a surface triangle: `vertices` with barycentric `weights`.
   */
  PALPATE_CONTACT_KIND_TRIANGLE = 1,
};
#ifndef __cplusplus
#if __STDC_VERSION__ >= 202311L
typedef enum palpate_contact_kind palpate_contact_kind;
#else
typedef uint32_t palpate_contact_kind;
#endif // __STDC_VERSION__ >= 202311L
#endif // __cplusplus

/*
 What a tool point does in a tick (`palpate_tool::action`).
 */
enum palpate_tool_action
#if defined(__cplusplus) || __STDC_VERSION__ >= 202311L
  : uint32_t
#endif // defined(__cplusplus) || __STDC_VERSION__ >= 202311L
 {
  /*
   A probe: touches, slides without friction, lets go when it would
   pull.
   */
  PALPATE_TOOL_ACTION_TOUCH = 0,
  /*
   A closed grasper jaw: the contact it has when the grip closes is
   held (it follows the jaw and may pull) until the action changes.
   */
  PALPATE_TOOL_ACTION_GRIP = 1,
  /*
   An enabled blade from the point along `blade_m`: cuts the
   tensor-mass model at each physics update; a probe on the
   pre-computed model (`cut_refused` says so).
   */
  PALPATE_TOOL_ACTION_CUT = 2,
};
#ifndef __cplusplus
#if __STDC_VERSION__ >= 202311L
typedef enum palpate_tool_action palpate_tool_action;
#else
typedef uint32_t palpate_tool_action;
#endif // __STDC_VERSION__ >= 202311L
#endif // __cplusplus

/*
 The elastic law of the tensor-mass model (`palpate_physics_config::law`).
 */
enum palpate_law
#if defined(__cplusplus) || __STDC_VERSION__ >= 202311L
  : uint32_t
#endif // defined(__cplusplus) || __STDC_VERSION__ >= 202311L
 {
  /*
   Linear elasticity on vertex and edge tensors (RR-3510 §5).
   */
  PALPATE_LAW_LINEAR = 0,
  /*
   St Venant-Kirchhoff, per tet (Picinbono 2001; the fast form).
   */
  PALPATE_LAW_STVK = 1,
  /*
   St Venant-Kirchhoff by the split terms on vertices, edges,
   triangles and tets (Picinbono 2001 eq. 13-15; more memory).
   */
  PALPATE_LAW_STVK_TENSORS = 2,
  /*
   Co-rotational linear, per tet (Muller & Gross 2004).
   */
  PALPATE_LAW_COROTATIONAL = 3,
  /*
   Compressible neo-Hookean, per tet (Bonet & Wood).
   */
  PALPATE_LAW_NEO_HOOKEAN = 4,
};
#ifndef __cplusplus
#if __STDC_VERSION__ >= 202311L
typedef enum palpate_law palpate_law;
#else
typedef uint32_t palpate_law;
#endif // __STDC_VERSION__ >= 202311L
#endif // __cplusplus

/*
 The explicit integrator (`palpate_physics_config::integrator`).
 */
enum palpate_integrator
#if defined(__cplusplus) || __STDC_VERSION__ >= 202311L
  : uint32_t
#endif // defined(__cplusplus) || __STDC_VERSION__ >= 202311L
 {
  /*
   Explicit Euler.
   */
  PALPATE_INTEGRATOR_EXPLICIT_EULER = 0,
  /*
   Symplectic Euler (stable up to `2/ω_max`).
   */
  PALPATE_INTEGRATOR_SYMPLECTIC_EULER = 1,
  /*
   Fourth-order Runge-Kutta (needs `4N` more vectors of memory).
   */
  PALPATE_INTEGRATOR_RK4 = 2,
  /*
   The central difference of Picinbono eq. 19.
   */
  PALPATE_INTEGRATOR_CENTRAL_DIFFERENCE = 3,
};
#ifndef __cplusplus
#if __STDC_VERSION__ >= 202311L
typedef enum palpate_integrator palpate_integrator;
#else
typedef uint32_t palpate_integrator;
#endif // __STDC_VERSION__ >= 202311L
#endif // __cplusplus

/*
 How the force is extrapolated between physics updates
 (`palpate_physics_config::extrapolation`).
 */
enum palpate_extrapolation
#if defined(__cplusplus) || __STDC_VERSION__ >= 202311L
  : uint32_t
#endif // defined(__cplusplus) || __STDC_VERSION__ >= 202311L
 {
  /*
   The secant ratio of the last period, each update's correction
   spread over the next period (the default).
   */
  PALPATE_EXTRAPOLATION_SECANT = 0,
  /*
   The contact stiffness with the rest of the mesh frozen.
   */
  PALPATE_EXTRAPOLATION_INSTANTANEOUS = 1,
};
#ifndef __cplusplus
#if __STDC_VERSION__ >= 202311L
typedef enum palpate_extrapolation palpate_extrapolation;
#else
typedef uint32_t palpate_extrapolation;
#endif // __STDC_VERSION__ >= 202311L
#endif // __cplusplus

/*
 The details of the last failure recorded in it (opaque): pass a pointer
 to one as the last argument of a function that takes it (or `NULL` for
 none); on failure the function writes the details there, and
 `palpate_error_message` formats them. A success leaves it as it was.
 Zero-initialize it (static storage is): an error never written formats
 as the empty string.
 */
typedef struct palpate_error {
  uint64_t opaque[PALPATE_ERROR_WORDS];
} palpate_error;

/*
 A loaded table (opaque): a validated view of the caller's bytes, which
 must stay in place and unchanged while the table and anything created
 from it are used. Do not copy it: pass its address. Zero-initialize it
 (static storage is).
 */
typedef struct palpate_table {
  uint64_t opaque[PALPATE_TABLE_WORDS];
} palpate_table;

/*
 A table's counts (`palpate_table_get_info`); 0 where a kind has none.
 */
typedef struct palpate_table_info {
  /*
   The table's kind.
   */
  palpate_table_kind kind;
  /*
   Mesh vertices: the length of a displacement field.
   */
  uint32_t vertex_count;
  /*
   Free (not fixed) vertices: pre-computed and interface tables.
   */
  uint32_t free_count;
  /*
   Touchable (free boundary-surface) vertices: pre-computed tables.
   */
  uint32_t touchable_count;
  /*
   Tets: tensor-mass tables.
   */
  uint32_t tet_count;
  /*
   Edges: tensor-mass tables.
   */
  uint32_t edge_count;
  /*
   Connection nodes: interface tables.
   */
  uint32_t connection_count;
} palpate_table_info;

/*
 A scripted contact: a point of the surface and the displacement the
 tool imposes on it.
 */
typedef struct palpate_contact {
  /*
   A `palpate_contact_kind` value.
   */
  uint32_t kind;
  /*
   Mesh vertex indices (0-based): a vertex contact uses `vertices[0]`;
   a triangle contact its three vertices, a triangle of the table's
   boundary surface in any order.
   */
  uint32_t vertices[3];
  /*
   A triangle contact's barycentric weights (each in `[0, 1]`, summing
   to 1); ignored for a vertex contact.
   */
  float weights[3];
  /*
   Imposed displacement of the contact point from rest, m.
   */
  float displacement_m[3];
} palpate_contact;

/*
 The kernel's contact solution inside a `palpate_solution` (opaque).
 */
typedef struct palpate_solution_state {
  uint64_t opaque[PALPATE_SOLUTION_WORDS];
} palpate_solution_state;

/*
 A solved contact set (`palpate_precomputed_solve`).
 */
typedef struct palpate_solution {
  /*
   Contacts solved (0 to `PALPATE_MAX_CONTACTS`).
   */
  uint32_t count;
  /*
   `-Σ g_p`: the force of the tissue on the tool, what the device
   renders, N (`+0` without contact).
   */
  float device_force_n[3];
  /*
   `g_p`: the force the tool applies to the tissue at each contact, N,
   in the order given; zero from `count` on.
   */
  float contact_forces_n[PALPATE_MAX_CONTACTS][3];
  /*
   The kernel's solution, for `palpate_precomputed_displacements`.
   */
  struct palpate_solution_state state;
} palpate_solution;

/*
 A haptic loop's settings (`palpate_loop_config_default` gives the
 host's defaults).
 */
typedef struct palpate_loop_config {
  /*
   Tool points, 1 to `PALPATE_TOOL_POINTS`: `palpate_*_loop_tick` takes
   this many.
   */
  uint32_t tool_points;
  /*
   Radius of each tool point's sphere, m (finite, > 0).
   */
  float radius_m;
  /*
   Haptic period, s (finite, > 0; 1 kHz: 0.001).
   */
  float dt_s;
  /*
   Largest force magnitude sent to the device, N (finite, > 0).
   */
  float max_force_n;
  /*
   Largest change of the force vector per second, N/s (finite, > 0).
   */
  float max_slew_n_per_s;
} palpate_loop_config;

/*
 A haptic loop over a pre-computed table (opaque). It reads its table
 handle, which must outlive it and stay in place. Do not copy it: pass
 its address. Not thread-safe: one caller at a time (the haptic task).
 */
typedef struct palpate_precomputed_loop {
  uint64_t opaque[PALPATE_PRECOMPUTED_LOOP_WORDS];
} palpate_precomputed_loop;

/*
 A tool point's input for one tick.
 */
typedef struct palpate_tool {
  /*
   The tool sphere's centre, m (a non-finite value latches
   `PALPATE_OUTPUT_STATUS_FAULT_NON_FINITE_INPUT`).
   */
  float position_m[3];
  /*
   A `palpate_tool_action` value.
   */
  uint32_t action;
  /*
   A blade's extent from the point, m (`PALPATE_TOOL_ACTION_CUT` only).
   */
  float blade_m[3];
} palpate_tool;

/*
 What the device receives each tick.
 */
typedef struct palpate_force {
  /*
   Force on the hand, N (after the supervisor).
   */
  float force_n[3];
  /*
   Ok, clamped, the latched fault, or a tool point inside the body.
   */
  palpate_output_status status;
  /*
   Tool points in contact.
   */
  uint8_t contacts;
  /*
   Tool points whose new contact was refused this tick (capacity
   reached, or a contact the model refused).
   */
  uint8_t refused;
  /*
   A blade touches a tissue that cannot be cut (the pre-computed model).
   */
  bool cut_refused;
} palpate_force;

/*
 The tensor-mass model's physics (the dynamic loop's tissue, the hybrid's
 tensor-mass region). The caller calls `palpate_*_loop_physics_update`
 every few ticks; each runs `substeps` steps of `dt_s`.
 */
typedef struct palpate_physics_config {
  /*
   A `palpate_law` value.
   */
  uint32_t law;
  /*
   Incompressibility penalty `γ`, N (Picinbono 2001 §3.2), 0 for none.
   */
  float incompressibility_n;
  /*
   Mass-proportional damping `c`, 1/s (finite, ≥ 0).
   */
  float damping_per_s;
  /*
   Gravity on every free vertex, m/s².
   */
  float gravity_m_s2[3];
  /*
   Divergence bound: largest displacement of any vertex, m (≥ 0).
   */
  float max_displacement_m;
  /*
   Divergence bound: largest kinetic energy, J (≥ 0; `INFINITY` for
   none).
   */
  float max_kinetic_energy_j;
  /*
   A `palpate_integrator` value.
   */
  uint32_t integrator;
  /*
   A `palpate_extrapolation` value.
   */
  uint32_t extrapolation;
  /*
   Step, s (finite, > 0, below the integrator's critical step:
   `palpate dynamic critical-dt`).
   */
  float dt_s;
  /*
   Steps per physics update, 1 to 10000.
   */
  uint32_t substeps;
  /*
   Most tets the blades remove per update, 1 to 64.
   */
  uint32_t cut_capacity_tets;
  /*
   The push of a blade's sphere at which the tet ahead gives way, N
   (finite, > 0; the host's default is 0.2).
   */
  float cut_force_n;
  /*
   Most tets tearing removes per update, 1 to 64; 0 for no tearing.
   */
  uint32_t tear_capacity_tets;
  /*
   Tearing: largest `|V − V₀| / V₀` of a tet, 0 for no limit.
   */
  float tear_volume_change;
  /*
   Tearing: largest mean edge elongation of a tet, 0 for no limit.
   */
  float tear_mean_elongation;
  /*
   Tearing: largest single edge elongation, 0 for no limit.
   */
  float tear_max_elongation;
} palpate_physics_config;

/*
 A haptic loop over a tensor-mass table (opaque). Its memory block must
 outlive it, in place and untouched (the table's bytes too). Do not copy
 it: pass its address. Not thread-safe: tick and physics update from one
 task, or under one lock.
 */
typedef struct palpate_dynamic_loop {
  uint64_t opaque[PALPATE_DYNAMIC_LOOP_WORDS];
} palpate_dynamic_loop;

/*
 What a physics update did.
 */
typedef struct palpate_physics_report {
  /*
   Kinetic energy of the tensor-mass model after the update, J.
   */
  float kinetic_energy_j;
  /*
   Force evaluations (passes over vertices and edges) of the last step.
   */
  uint32_t force_evaluations;
  /*
   Tets the update removed (blades, then tearing):
   `palpate_*_loop_removed_tets` lists them.
   */
  uint32_t removed_tets;
} palpate_physics_report;

/*
 A haptic loop over the hybrid model (opaque), as `palpate_dynamic_loop`.
 */
typedef struct palpate_hybrid_loop {
  uint64_t opaque[PALPATE_HYBRID_LOOP_WORDS];
} palpate_hybrid_loop;

#ifdef __cplusplus
extern "C" {
#endif // __cplusplus

/*
 The ABI version of this library, `PALPATE_ABI_VERSION`.
 */
uint32_t palpate_abi_version(void);

/*
 A short, static, NUL-terminated description of status code `status`
 ("unknown status code" for a number that is no code). Never null.
 */
const char *palpate_status_message(uint32_t status);

/*
 Writes the message of the failure recorded in `error` into `buffer`
 (`capacity` bytes, NUL-terminated, truncated to fit), the kernel's own
 words (for example `contact 1: vertex 0 is fixed`). Returns the
 message's full length in bytes without the NUL, as `snprintf` does: the
 message was truncated if that is `>= capacity`. `buffer` may be `NULL`
 when `capacity` is 0 (to ask for the length). An `error` that is `NULL`,
 misaligned or never written gives the empty message (0).

 # Safety

 `error` is `NULL` or points to a readable `palpate_error`; `buffer`
 points to `capacity` writable bytes (any alignment).
 */
size_t palpate_error_message(const struct palpate_error *error, char *buffer, size_t capacity);

/*
 Loads and validates a pre-computed table (`palpate tables build`, f32)
 of `len` bytes at `bytes` into `table`. The bytes must start on a
 16-byte boundary (`PALPATE_STATUS_TABLE_MISALIGNED` otherwise) and stay in
 place and unchanged while `table` and anything created from it are
 used; they are read in place, never copied. Cost: one pass over the
 table (the CRC-32 and every check), not for the haptic path.

 # Safety

 `table` is `NULL` or points to a writable `palpate_table` that no
 live loop uses; `bytes` is `NULL` or points to `len` readable bytes;
 `error` is `NULL` or points to a writable `palpate_error`.
 */
palpate_status palpate_precomputed_table_load(struct palpate_table *table,
                                              const uint8_t *bytes,
                                              size_t len,
                                              struct palpate_error *error);

/*
 Loads and validates a tensor-mass table (`palpate tables build --kind
 tensor-mass`, f32), as `palpate_precomputed_table_load`.

 # Safety

 As `palpate_precomputed_table_load`.
 */
palpate_status palpate_tensor_mass_table_load(struct palpate_table *table,
                                              const uint8_t *bytes,
                                              size_t len,
                                              struct palpate_error *error);

/*
 Loads and validates a hybrid interface table (`palpate scene tables`,
 f32), as `palpate_precomputed_table_load`.

 # Safety

 As `palpate_precomputed_table_load`.
 */
palpate_status palpate_interface_table_load(struct palpate_table *table,
                                            const uint8_t *bytes,
                                            size_t len,
                                            struct palpate_error *error);

/*
 Writes `table`'s kind and counts to `info`.

 # Safety

 `table` is `NULL` or points to a `palpate_table`; `info` is `NULL` or
 points to a writable `palpate_table_info`.
 */
palpate_status palpate_table_get_info(const struct palpate_table *table,
                                      struct palpate_table_info *info);

/*
 Solves `count` contacts at `contacts` on pre-computed table `table`
 (MODELS.md §2: the point compliances `C_pq`, a block Cholesky of the
 `3m × 3m` system on the stack) and writes the forces to `solution`.
 Bounded: `O(m³)` with `m ≤ PALPATE_MAX_CONTACTS`, independent of the
 mesh. No contact gives zero force. Refused, with the kernel's reason
 (`PALPATE_STATUS_CONTACT_*`, details in `error`): more than
 `PALPATE_MAX_CONTACTS` contacts, a vertex out of range, fixed or not on
 the surface, a triangle that is not one of the surface's, bad weights,
 non-finite input, two contacts on one vertex, an ill-conditioned system.

 # Safety

 `table` is `NULL` or points to a `palpate_table`; `contacts` is
 `NULL` or points to `count` readable `palpate_contact` (it may be
 `NULL` when `count` is 0); `solution` is `NULL` or points to a writable
 `palpate_solution`; `error` is `NULL` or points to a writable
 `palpate_error`.
 */
palpate_status palpate_precomputed_solve(const struct palpate_table *table,
                                         const struct palpate_contact *contacts,
                                         size_t count,
                                         struct palpate_solution *solution,
                                         struct palpate_error *error);

/*
 Writes the displacement of every vertex (m, mesh vertex order; fixed
 vertices zero) for `solution` to `displacements_m`, which holds
 `vertex_count` entries: the table's vertex count
 (`PALPATE_STATUS_DISPLACEMENT_BUFFER` otherwise). MODELS.md §2:
 `u_n = Σ_q Σ_b β^q_b C_{n v^q_b} g_q`. `table` is the table `solution`
 was solved on. Not needed by the haptic path (a renderer's call).

 # Safety

 `table` and `solution` are `NULL` or point to a table and a solution;
 `displacements_m` is `NULL` or points to `vertex_count` writable,
 4-byte-aligned `float[3]`; `error` is `NULL` or points to a writable
 `palpate_error`.
 */
palpate_status palpate_precomputed_displacements(const struct palpate_table *table,
                                                 const struct palpate_solution *solution,
                                                 float (*displacements_m)[3],
                                                 size_t vertex_count,
                                                 struct palpate_error *error);

/*
 The host's defaults (`palpate session run` scenes): one tool point of
 radius 2 mm, 1 kHz, 4 N, 2000 N/s (full force in 2 ms).
 */
struct palpate_loop_config palpate_loop_config_default(void);

/*
 Creates in `haptic` a loop at rest (no contact, zero force) over
 pre-computed table `table` with `config`. Refused: a table of another
 kind, `tool_points` outside 1 to `PALPATE_TOOL_POINTS`
 (`PALPATE_STATUS_BAD_ARGUMENT`), a radius or period not finite and
 positive, limits not finite and positive. On failure `haptic` is marked
 not initialized.

 # Safety

 `haptic` is `NULL` or points to a writable `palpate_precomputed_loop`;
 `table` is `NULL` or points to a table that outlives the loop, in place;
 `config` is `NULL` or points to a `palpate_loop_config`; `error` is
 `NULL` or points to a writable `palpate_error`.
 */
palpate_status palpate_precomputed_loop_create(struct palpate_precomputed_loop *haptic,
                                               const struct palpate_table *table,
                                               const struct palpate_loop_config *config,
                                               struct palpate_error *error);

/*
 One haptic tick: the `count` tool points at `tools` (`count` is the
 loop's `tool_points`) are tracked or detected on the surface, the
 contacts solved, the force passed through the supervisor; the result to
 `force`. A non-finite position or a model fault is not a failure of the
 call: it latches a fault in `force->status` (zero force until
 `palpate_precomputed_loop_reset`). Bounded: detection and tracking per
 point, at most `PALPATE_TOOL_POINTS + 1` solves of at most
 `PALPATE_MAX_CONTACTS` contacts.

 # Safety

 `haptic` is `NULL` or points to a loop nothing else uses during the
 call; `tools` is `NULL` or points to `count` readable `palpate_tool`;
 `force` is `NULL` or points to a writable `palpate_force`.
 */
palpate_status palpate_precomputed_loop_tick(struct palpate_precomputed_loop *haptic,
                                             const struct palpate_tool *tools,
                                             size_t count,
                                             struct palpate_force *force);

/*
 Clears a latched fault and every contact; the force ramps up from zero
 at the slew limit.

 # Safety

 `haptic` is `NULL` or points to a loop nothing else uses during the call.
 */
palpate_status palpate_precomputed_loop_reset(struct palpate_precomputed_loop *haptic);

/*
 Writes the displacement of every vertex (m, mesh vertex order) for the
 last tick's contacts to `displacements_m` (`vertex_count` entries: the
 table's vertex count); all zero before the first contact and after a
 fault. For a renderer, at its own rate: `O(F)` per contact term, not on
 the haptic path.

 # Safety

 `haptic` is `NULL` or points to a loop; `displacements_m` is `NULL` or
 points to `vertex_count` writable, 4-byte-aligned `float[3]`; `error`
 is `NULL` or points to a writable `palpate_error`.
 */
palpate_status palpate_precomputed_loop_displacements(const struct palpate_precomputed_loop *haptic,
                                                      float (*displacements_m)[3],
                                                      size_t vertex_count,
                                                      struct palpate_error *error);

/*
 Writes to `bytes` the size of the memory block a dynamic loop over
 tensor-mass table `table` with `physics` needs (aligned to
 `PALPATE_MEMORY_ALIGN`): `141 N + 36 E + 72 F + T` bytes and a few of
 alignment for `N` vertices, `E` edges, `F` mesh triangles (every tet
 face once) and `T` tets; RK4 adds `48 N`, the split St Venant-Kirchhoff
 form `16 N + 64 E + 60 F + 12 T`. The firmware box (64 vertices, 279
 edges, 378 faces, 162 tets): 46 456 bytes.

 # Safety

 `table` and `physics` are `NULL` or point to a table and a
 `palpate_physics_config`; `bytes` is `NULL` or points to a writable
 `size_t`.
 */
palpate_status palpate_dynamic_memory_size(const struct palpate_table *table,
                                           const struct palpate_physics_config *physics,
                                           size_t *bytes);

/*
 Creates in `haptic` a loop at rest over tensor-mass table `table` with
 `config` and `physics`, its buffers in `memory` (`memory_bytes` bytes,
 aligned to `PALPATE_MEMORY_ALIGN`, at least
 `palpate_dynamic_memory_size`). The memory's contents are overwritten;
 it must outlive the loop, in place and untouched. Refused: a table of
 another kind, bad configuration or physics (`PALPATE_STATUS_BAD_ARGUMENT`
 for an enum value out of range, the kernel's code otherwise), too
 little memory. On failure `haptic` is marked not initialized.

 # Safety

 `haptic` is `NULL` or points to a writable `palpate_dynamic_loop`;
 `table` is `NULL` or points to a table whose bytes outlive the loop;
 `config` and `physics` are `NULL` or point to their structs; `memory` is
 `NULL` or points to `memory_bytes` writable bytes nothing else uses
 while the loop lives; `error` is `NULL` or points to a writable
 `palpate_error`.
 */
palpate_status palpate_dynamic_loop_create(struct palpate_dynamic_loop *haptic,
                                           const struct palpate_table *table,
                                           const struct palpate_loop_config *config,
                                           const struct palpate_physics_config *physics,
                                           void *memory,
                                           size_t memory_bytes,
                                           struct palpate_error *error);

/*
 One haptic tick, as `palpate_precomputed_loop_tick`: between physics
 updates the force is extrapolated from the contact stiffness and the
 tool's motion; a blade (`PALPATE_TOOL_ACTION_CUT`) cuts at the next update.

 # Safety

 As `palpate_precomputed_loop_tick`.
 */
palpate_status palpate_dynamic_loop_tick(struct palpate_dynamic_loop *haptic,
                                         const struct palpate_tool *tools,
                                         size_t count,
                                         struct palpate_force *force);

/*
 One physics update with the current contacts at the last tick's tool
 positions and its blades: cut, impose, `substeps` steps, tear, re-bin
 the surface (call it every few ticks, after a tick). Its report to
 `report` (may be `NULL`). On failure (divergence: `PALPATE_STATUS_FAULT_*`)
 the next tick latches a model fault (zero force) until
 `palpate_dynamic_loop_reset`.

 # Safety

 `haptic` is `NULL` or points to a loop nothing else uses during the
 call; `report` is `NULL` or points to a writable
 `palpate_physics_report`; `error` is `NULL` or points to a writable
 `palpate_error`.
 */
palpate_status palpate_dynamic_loop_physics_update(struct palpate_dynamic_loop *haptic,
                                                   struct palpate_physics_report *report,
                                                   struct palpate_error *error);

/*
 Copies the tets the last physics update removed (tensor-mass table
 numbering, removal order) to `tets` (`capacity` entries; may be `NULL`
 when 0) and their number to `count`. `PALPATE_STATUS_BAD_ARGUMENT` when they
 do not fit (`count` is still written).

 # Safety

 `haptic` is `NULL` or points to a loop; `tets` is `NULL` or points to
 `capacity` writable `uint32_t`; `count` is `NULL` or points to a
 writable `size_t`.
 */
palpate_status palpate_dynamic_loop_removed_tets(const struct palpate_dynamic_loop *haptic,
                                                 uint32_t *tets,
                                                 size_t capacity,
                                                 size_t *count);

/*
 Back to rest: every tet alive again, no contact, no fault; the force
 ramps up from zero at the slew limit.

 # Safety

 `haptic` is `NULL` or points to a loop nothing else uses during the call.
 */
palpate_status palpate_dynamic_loop_reset(struct palpate_dynamic_loop *haptic);

/*
 Writes the displacement of every vertex (m, table vertex order) at the
 last physics update to `displacements_m` (`vertex_count` entries).
 Refused while the model is faulted (`PALPATE_STATUS_FAULT_*`).

 # Safety

 `haptic` is `NULL` or points to a loop; `displacements_m` is `NULL` or
 points to `vertex_count` writable, 4-byte-aligned `float[3]`; `error`
 is `NULL` or points to a writable `palpate_error`.
 */
palpate_status palpate_dynamic_loop_displacements(const struct palpate_dynamic_loop *haptic,
                                                  float (*displacements_m)[3],
                                                  size_t vertex_count,
                                                  struct palpate_error *error);

/*
 Writes to `bytes` the size of the memory block a hybrid loop over the
 three tables with `physics` (the tensor-mass region's) needs.

 # Safety

 `precomputed`, `dynamic`, `interface` and `physics` are `NULL` or point
 to a table of each kind and a `palpate_physics_config`; `bytes` is
 `NULL` or points to a writable `size_t`.
 */
palpate_status palpate_hybrid_memory_size(const struct palpate_table *precomputed,
                                          const struct palpate_table *dynamic,
                                          const struct palpate_table *interface,
                                          const struct palpate_physics_config *physics,
                                          size_t *bytes);

/*
 Creates in `haptic` a hybrid loop at rest over its pre-computed region's
 table `precomputed`, its tensor-mass region's table `dynamic` and the
 `interface` (the three of one `palpate scene tables` build:
 `PALPATE_STATUS_HYBRID_MISMATCH` otherwise), as
 `palpate_dynamic_loop_create`, its buffers in `memory` (at least
 `palpate_hybrid_memory_size` bytes).

 # Safety

 As `palpate_dynamic_loop_create`, with three table handles.
 */
palpate_status palpate_hybrid_loop_create(struct palpate_hybrid_loop *haptic,
                                          const struct palpate_table *precomputed,
                                          const struct palpate_table *dynamic,
                                          const struct palpate_table *interface,
                                          const struct palpate_loop_config *config,
                                          const struct palpate_physics_config *physics,
                                          void *memory,
                                          size_t memory_bytes,
                                          struct palpate_error *error);

/*
 One haptic tick, as `palpate_dynamic_loop_tick`: contacts on the
 pre-computed region are solved every tick, those on the tensor-mass
 region extrapolated between physics updates.

 # Safety

 As `palpate_precomputed_loop_tick`.
 */
palpate_status palpate_hybrid_loop_tick(struct palpate_hybrid_loop *haptic,
                                        const struct palpate_tool *tools,
                                        size_t count,
                                        struct palpate_force *force);

/*
 One physics update, as `palpate_dynamic_loop_physics_update`: the
 pre-computed contacts' forces passed to the connection nodes, the
 tensor-mass region stepped with the condensed region's force, the
 background and the whole surface refreshed.

 # Safety

 As `palpate_dynamic_loop_physics_update`.
 */
palpate_status palpate_hybrid_loop_physics_update(struct palpate_hybrid_loop *haptic,
                                                  struct palpate_physics_report *report,
                                                  struct palpate_error *error);

/*
 The tets the last physics update removed (the tensor-mass region's
 table numbering), as `palpate_dynamic_loop_removed_tets`.

 # Safety

 As `palpate_dynamic_loop_removed_tets`.
 */
palpate_status palpate_hybrid_loop_removed_tets(const struct palpate_hybrid_loop *haptic,
                                                uint32_t *tets,
                                                size_t capacity,
                                                size_t *count);

/*
 Back to rest, as `palpate_dynamic_loop_reset` (both regions).

 # Safety

 As `palpate_dynamic_loop_reset`.
 */
palpate_status palpate_hybrid_loop_reset(struct palpate_hybrid_loop *haptic);

/*
 Writes the displacement of every mesh vertex (m, mesh vertex order) to
 `displacements_m` (`vertex_count` entries, the interface's vertex
 count): the tensor-mass region's at the last physics update, the
 pre-computed region's background plus its response to the last tick's
 contacts. Refused while the tensor-mass region is faulted.

 # Safety

 As `palpate_dynamic_loop_displacements`.
 */
palpate_status palpate_hybrid_loop_displacements(const struct palpate_hybrid_loop *haptic,
                                                 float (*displacements_m)[3],
                                                 size_t vertex_count,
                                                 struct palpate_error *error);

#ifdef __cplusplus
}  // extern "C"
#endif  // __cplusplus

#endif  /* PALPATE_H */

/*
 * The C ABI's contract from C (tools/ffi-check.sh compiles it with the
 * system C compiler against the host's libpalpate_ffi.a and runs it under
 * valgrind memcheck): every function of palpate.h, with real tables, with
 * NULL pointers, short buffers, misaligned tables, handles and memory,
 * handles never created or whose creation failed, out-of-range arguments,
 * each kernel refusal, and tables corrupted before and after their load.
 * Each call must give its status code, never a crash (valgrind: no invalid
 * read or write either).
 *
 *   abi_test TABLE TENSOR_TABLE HYBRID_DIR HOST_REPLAY
 *
 * TABLE and TENSOR_TABLE are the firmware box's f32 tables
 * (tools/box-table.sh, with --tensor-mass), HYBRID_DIR the hybrid box's
 * three (tools/hybrid-tables.sh), HOST_REPLAY the output of `palpate
 * precomputed replay TABLE tools/firmware-m4f/sequence.txt`, whose first
 * line the scripted solve must reproduce bit for bit.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "palpate.h"

static int checks, failures;

#define CHECK(condition)                                                                 \
    do {                                                                                 \
        checks++;                                                                        \
        if (!(condition)) {                                                              \
            failures++;                                                                  \
            fprintf(stderr, "%s:%d: FAILED: %s\n", __FILE__, __LINE__, #condition);      \
        }                                                                                \
    } while (0)

/* `call` returns `expected` (a palpate_status). */
#define EXPECT(expected, call)                                                           \
    do {                                                                                 \
        palpate_status got_ = (call);                                                    \
        checks++;                                                                        \
        if (got_ != (palpate_status)(expected)) {                                        \
            failures++;                                                                  \
            fprintf(stderr, "%s:%d: %s\n  gave %u (%s), expected %u (%s)\n", __FILE__,   \
                    __LINE__, #call, (unsigned)got_, palpate_status_message(got_),       \
                    (unsigned)(expected), palpate_status_message(expected));             \
        }                                                                                \
    } while (0)

/* A file's bytes at offset `skew` of a 16-byte-aligned buffer. */
typedef struct {
    unsigned char *buffer;
    unsigned char *bytes;
    size_t len;
} table_file;

static table_file read_table(const char *path, size_t skew) {
    table_file t = {0};
    FILE *file = fopen(path, "rb");
    if (file == NULL || fseek(file, 0, SEEK_END) != 0) {
        perror(path);
        exit(2);
    }
    long len = ftell(file);
    t.len = (size_t)len;
    t.buffer = aligned_alloc(16, (t.len + skew + 15) / 16 * 16);
    t.bytes = t.buffer + skew;
    if (t.buffer == NULL || fseek(file, 0, SEEK_SET) != 0 ||
        fread(t.bytes, 1, t.len, file) != t.len) {
        perror(path);
        exit(2);
    }
    fclose(file);
    return t;
}

static void free_table(table_file *t) { free(t->buffer); }

/* palpate_error_message as a string (static buffer). */
static const char *message(const palpate_error *error) {
    static char text[256];
    palpate_error_message(error, text, sizeof text);
    return text;
}

/* The replay's line for a solved step (tools/script: `step <i> device ...
   contacts ... umax <u>`), floats as their bit patterns. */
static void replay_line(char *out, size_t cap, uint32_t step, const palpate_solution *s,
                        float umax) {
    uint32_t bits;
    int n = snprintf(out, cap, "step %u device", step);
#define BITS(x) (memcpy(&bits, &(x), 4), bits)
    for (int i = 0; i < 3; i++) n += snprintf(out + n, cap - n, " 0x%08x", BITS(s->device_force_n[i]));
    n += snprintf(out + n, cap - n, " contacts");
    for (uint32_t c = 0; c < s->count; c++)
        for (int i = 0; i < 3; i++)
            n += snprintf(out + n, cap - n, " 0x%08x", BITS(s->contact_forces_n[c][i]));
    snprintf(out + n, cap - n, " umax 0x%08x", BITS(umax));
#undef BITS
}

static palpate_contact vertex_contact(uint32_t v, float dz) {
    palpate_contact c = {PALPATE_CONTACT_KIND_VERTEX, {v, 0, 0}, {0, 0, 0}, {0, 0, dz}};
    return c;
}

static palpate_contact triangle_contact(uint32_t a, uint32_t b, uint32_t c, float wa, float wb,
                                        float wc, float dz) {
    palpate_contact t = {PALPATE_CONTACT_KIND_TRIANGLE, {a, b, c}, {wa, wb, wc}, {0, 0, dz}};
    return t;
}

/* Box of tools/firmware-m4f/mesh: 64 vertices, top face z = 0.03 m. */
#define VERTICES 64

static void test_versions_and_messages(void) {
    CHECK(palpate_abi_version() == PALPATE_ABI_VERSION);
    CHECK(PALPATE_TABLE_FORMAT_VERSION == 6);
    /* Every code has its own message; an unknown number has one too. */
    const palpate_status codes[] = {PALPATE_STATUS_OK, PALPATE_STATUS_NULL_POINTER,
                                    PALPATE_STATUS_TABLE_CHECKSUM_MISMATCH,
                                    PALPATE_STATUS_CONTACT_FIXED_VERTEX,
                                    PALPATE_STATUS_HYBRID_MISMATCH};
    for (size_t i = 0; i < sizeof codes / sizeof codes[0]; i++) {
        CHECK(palpate_status_message(codes[i]) != NULL);
        CHECK(strcmp(palpate_status_message(codes[i]), "unknown status code") != 0);
    }
    CHECK(strcmp(palpate_status_message(PALPATE_STATUS_OK), "ok") == 0);
    CHECK(strcmp(palpate_status_message(999), "unknown status code") == 0);
    CHECK(strcmp(palpate_status_message(0xFFFFFFFFu), "unknown status code") == 0);
    /* An error never written, or NULL: the empty message. */
    palpate_error never = {{0}};
    char text[8] = "x";
    CHECK(palpate_error_message(&never, text, sizeof text) == 0 && text[0] == '\0');
    CHECK(palpate_error_message(NULL, text, sizeof text) == 0);
    CHECK(palpate_error_message(NULL, NULL, 0) == 0);
}

static void test_tables(const char *path, const char *tensor_path, const char *replay_path) {
    table_file t = read_table(path, 0);
    palpate_table table = {{0}};
    palpate_error error = {{0}};
    palpate_table_info info;

    /* NULL pointers. */
    EXPECT(PALPATE_STATUS_NULL_POINTER, palpate_precomputed_table_load(NULL, t.bytes, t.len, &error));
    EXPECT(PALPATE_STATUS_NULL_POINTER, palpate_precomputed_table_load(&table, NULL, t.len, &error));
    CHECK(strcmp(message(&error), "a required pointer is null") == 0);
    EXPECT(PALPATE_STATUS_NULL_POINTER, palpate_table_get_info(NULL, &info));
    /* A handle never loaded. */
    EXPECT(PALPATE_STATUS_NOT_INITIALIZED, palpate_table_get_info(&table, &info));
    /* A misaligned handle. */
    static uint64_t storage[sizeof(palpate_table) / 8 + 1];
    palpate_table *skewed = (palpate_table *)((unsigned char *)storage + 4);
    EXPECT(PALPATE_STATUS_MISALIGNED, palpate_precomputed_table_load(skewed, t.bytes, t.len, NULL));

    /* Short, truncated, padded, not a table. */
    EXPECT(PALPATE_STATUS_TABLE_TOO_SHORT, palpate_precomputed_table_load(&table, t.bytes, 10, &error));
    CHECK(strcmp(message(&error), "table too short (10 bytes)") == 0);
    EXPECT(PALPATE_STATUS_TABLE_LENGTH_MISMATCH,
           palpate_precomputed_table_load(&table, t.bytes, t.len - 1, &error));
    static const unsigned char zeros[256] = {0};
    EXPECT(PALPATE_STATUS_TABLE_BAD_MAGIC, palpate_precomputed_table_load(&table, zeros, 256, &error));
    /* The wrong kind: a tensor-mass table loaded as pre-computed. */
    table_file tm = read_table(tensor_path, 0);
    EXPECT(PALPATE_STATUS_TABLE_WRONG_KIND,
           palpate_precomputed_table_load(&table, tm.bytes, tm.len, &error));
    CHECK(strcmp(message(&error), "table kind 2 is not the kind requested") == 0);
    EXPECT(PALPATE_STATUS_TABLE_WRONG_KIND,
           palpate_interface_table_load(&table, t.bytes, t.len, &error));
    /* A failed load leaves the handle not initialized. */
    EXPECT(PALPATE_STATUS_NOT_INITIALIZED, palpate_table_get_info(&table, &info));

    /* Misaligned bytes: 2 bytes off a 16-byte boundary (an f32 table's
       sections need at least 4). */
    table_file off = read_table(path, 2);
    EXPECT(PALPATE_STATUS_TABLE_MISALIGNED,
           palpate_precomputed_table_load(&table, off.bytes, off.len, &error));
    CHECK(strstr(message(&error), "is misaligned in memory") != NULL);
    free_table(&off);

    /* A bit flipped anywhere: the CRC-32 refuses it at load (every byte
       before the trailer is covered). */
    table_file flipped = read_table(path, 0);
    flipped.bytes[flipped.len / 2] ^= 0x10;
    EXPECT(PALPATE_STATUS_TABLE_CHECKSUM_MISMATCH,
           palpate_precomputed_table_load(&table, flipped.bytes, flipped.len, &error));
    CHECK(strncmp(message(&error), "checksum mismatch: stored CRC-32 0x", 35) == 0);
    free_table(&flipped);

    /* The real table. */
    EXPECT(PALPATE_STATUS_OK, palpate_precomputed_table_load(&table, t.bytes, t.len, &error));
    EXPECT(PALPATE_STATUS_NULL_POINTER, palpate_table_get_info(&table, NULL));
    EXPECT(PALPATE_STATUS_OK, palpate_table_get_info(&table, &info));
    CHECK(info.kind == PALPATE_TABLE_KIND_PRECOMPUTED && info.vertex_count == VERTICES &&
          info.free_count == 48 && info.touchable_count == 40 && info.tet_count == 0);

    /* The scripted solve: the first step of sequence.txt (vertex 53 pressed
       0.4 mm) must print exactly the host replay's first line. */
    palpate_solution solution;
    palpate_contact press = vertex_contact(53, -0.0004f);
    static float u[VERTICES][3];
    EXPECT(PALPATE_STATUS_OK, palpate_precomputed_solve(&table, &press, 1, &solution, &error));
    EXPECT(PALPATE_STATUS_OK, palpate_precomputed_displacements(&table, &solution, u, VERTICES, &error));
    float umax = 0.0f;
    for (int v = 0; v < VERTICES; v++)
        for (int i = 0; i < 3; i++)
            if (fabsf(u[v][i]) > umax) umax = fabsf(u[v][i]);
    char line[512], expected[512] = "";
    replay_line(line, sizeof line, 0, &solution, umax);
    FILE *replay = fopen(replay_path, "r");
    CHECK(replay != NULL && fgets(expected, sizeof expected, replay) != NULL);
    if (replay != NULL) fclose(replay);
    expected[strcspn(expected, "\n")] = '\0';
    CHECK(strcmp(line, expected) == 0);
    if (strcmp(line, expected) != 0) fprintf(stderr, "  C:    %s\n  host: %s\n", line, expected);
    /* The pressed vertex moved by the imposed 0.4 mm, and the device force
       is minus the contact force. */
    CHECK(fabsf(u[53][2] + 0.0004f) <= 1e-6f * 0.0004f); /* the f32 solve's residual */
    CHECK(solution.count == 1 && solution.device_force_n[2] == -solution.contact_forces_n[0][2]);
    CHECK(solution.device_force_n[2] > 0.0f);

    /* No contact: zero force (+0). */
    EXPECT(PALPATE_STATUS_OK, palpate_precomputed_solve(&table, NULL, 0, &solution, NULL));
    CHECK(solution.count == 0 && solution.device_force_n[0] == 0.0f && !signbit(solution.device_force_n[0]));

    /* Every refusal of a contact set, with the kernel's words. */
    struct {
        palpate_status status;
        palpate_contact contacts[5];
        size_t count;
        const char *message;
    } refused[] = {
        {PALPATE_STATUS_CONTACT_TOO_MANY,
         {vertex_contact(53, -1e-4f), vertex_contact(54, -1e-4f), vertex_contact(57, -1e-4f),
          vertex_contact(58, -1e-4f), vertex_contact(49, -1e-4f)},
         5, "5 contacts exceed the capacity of 4"},
        {PALPATE_STATUS_CONTACT_VERTEX_OUT_OF_RANGE, {vertex_contact(64, -1e-4f)}, 1,
         "contact 0: vertex 64 out of range"},
        {PALPATE_STATUS_CONTACT_FIXED_VERTEX, {vertex_contact(53, -1e-4f), vertex_contact(0, -1e-4f)},
         2, "contact 1: vertex 0 is fixed"},
        {PALPATE_STATUS_CONTACT_NOT_ON_SURFACE, {vertex_contact(21, -1e-4f)}, 1,
         "contact 0: vertex 21 is not on the boundary surface"},
        {PALPATE_STATUS_CONTACT_REPEATED_VERTEX, {triangle_contact(56, 56, 61, 0.2f, 0.3f, 0.5f, -1e-4f)},
         1, "contact 0: vertex 56 appears twice; a triangle contact needs three distinct vertices"},
        {PALPATE_STATUS_CONTACT_NOT_SURFACE_TRIANGLE,
         {triangle_contact(48, 51, 60, 0.2f, 0.3f, 0.5f, -1e-4f)}, 1,
         "contact 0: vertices 48,51,60 are not a triangle of the table's boundary surface"},
        {PALPATE_STATUS_CONTACT_BAD_WEIGHTS, {triangle_contact(56, 57, 61, 0.5f, 0.6f, 0.1f, -1e-4f)},
         1, "contact 0: barycentric weights must lie in [0, 1] and sum to 1"},
        {PALPATE_STATUS_CONTACT_NON_FINITE_INPUT, {vertex_contact(53, NAN)}, 1,
         "contact 0: non-finite displacement or weight"},
        {PALPATE_STATUS_CONTACT_DUPLICATE, {vertex_contact(53, -1e-4f), vertex_contact(53, -2e-4f)}, 2,
         "contacts 0 and 1 are on the same vertex"},
        {PALPATE_STATUS_CONTACT_ILL_CONDITIONED, {triangle_contact(0, 1, 5, 0.2f, 0.3f, 0.5f, 1e-3f)},
         1, "contact system singular or ill-conditioned at contact 0"},
    };
    for (size_t i = 0; i < sizeof refused / sizeof refused[0]; i++) {
        palpate_error e = {{0}};
        EXPECT(refused[i].status, palpate_precomputed_solve(&table, refused[i].contacts,
                                                            refused[i].count, &solution, &e));
        CHECK(strcmp(message(&e), refused[i].message) == 0);
        if (strcmp(message(&e), refused[i].message) != 0) fprintf(stderr, "  got: %s\n", message(&e));
    }
    /* A contact kind that is no palpate_contact_kind. */
    palpate_contact odd = vertex_contact(53, -1e-4f);
    odd.kind = 7;
    EXPECT(PALPATE_STATUS_BAD_ARGUMENT, palpate_precomputed_solve(&table, &odd, 1, &solution, NULL));
    EXPECT(PALPATE_STATUS_NULL_POINTER, palpate_precomputed_solve(&table, NULL, 1, &solution, NULL));
    EXPECT(PALPATE_STATUS_NULL_POINTER, palpate_precomputed_solve(&table, &press, 1, NULL, NULL));
    EXPECT(PALPATE_STATUS_NULL_POINTER, palpate_precomputed_solve(NULL, &press, 1, &solution, NULL));

    /* The message buffer: truncated to fit, NUL-terminated, the full length
       returned; a NULL buffer of capacity 0 asks for the length. */
    palpate_error fixed = {{0}};
    palpate_contact on_fixed = vertex_contact(0, -1e-4f);
    EXPECT(PALPATE_STATUS_CONTACT_FIXED_VERTEX, palpate_precomputed_solve(&table, &on_fixed, 1, &solution, &fixed));
    char small[8];
    size_t full = palpate_error_message(&fixed, small, sizeof small);
    CHECK(full == strlen("contact 0: vertex 0 is fixed") && strcmp(small, "contact") == 0);
    CHECK(palpate_error_message(&fixed, NULL, 0) == full);
    char one[1] = {'x'};
    CHECK(palpate_error_message(&fixed, one, 1) == full && one[0] == '\0');

    /* The displacement buffer: short, NULL, misaligned. */
    EXPECT(PALPATE_STATUS_OK, palpate_precomputed_solve(&table, &press, 1, &solution, NULL));
    EXPECT(PALPATE_STATUS_DISPLACEMENT_BUFFER,
           palpate_precomputed_displacements(&table, &solution, u, VERTICES - 1, &error));
    CHECK(strcmp(message(&error), "displacement buffer holds 63 vertices, the table has 64") == 0);
    EXPECT(PALPATE_STATUS_NULL_POINTER,
           palpate_precomputed_displacements(&table, &solution, NULL, VERTICES, NULL));
    float (*skewed_u)[3] = (float (*)[3])((unsigned char *)u + 1);
    EXPECT(PALPATE_STATUS_MISALIGNED,
           palpate_precomputed_displacements(&table, &solution, skewed_u, VERTICES - 1, NULL));
    /* A solution never solved. */
    palpate_solution blank;
    memset(&blank, 0, sizeof blank);
    EXPECT(PALPATE_STATUS_NOT_INITIALIZED,
           palpate_precomputed_displacements(&table, &blank, u, VERTICES, NULL));
    /* The wrong kind of table handle for the solve. */
    palpate_table tensor = {{0}};
    EXPECT(PALPATE_STATUS_OK, palpate_tensor_mass_table_load(&tensor, tm.bytes, tm.len, &error));
    EXPECT(PALPATE_STATUS_WRONG_TABLE, palpate_precomputed_solve(&tensor, &press, 1, &solution, NULL));
    EXPECT(PALPATE_STATUS_OK, palpate_table_get_info(&tensor, &info));
    CHECK(info.kind == PALPATE_TABLE_KIND_TENSOR_MASS && info.vertex_count == VERTICES &&
          info.tet_count == 162 && info.edge_count > 0);

    /* A table corrupted after its load: the view is trusted, so the numbers
       may be wrong, but every index the kernel reads from it is checked:
       each byte flipped in turn, then a solve, the field and a haptic tick
       run without an invalid access (valgrind checks every read). Loading
       the same bytes again finds the corruption. */
    palpate_precomputed_loop loop;
    memset(&loop, 0, sizeof loop);
    palpate_loop_config config = palpate_loop_config_default();
    EXPECT(PALPATE_STATUS_OK, palpate_precomputed_loop_create(&loop, &table, &config, NULL));
    for (size_t at = 0; at + 4 < t.len; at += 61) {
        palpate_force force;
        palpate_tool probe = {{0.012f, 0.013f, 0.0315f}, PALPATE_TOOL_ACTION_TOUCH, {0, 0, 0}};
        t.bytes[at] ^= 0xA5;
        (void)palpate_precomputed_solve(&table, &press, 1, &solution, NULL);
        (void)palpate_precomputed_displacements(&table, &solution, u, VERTICES, NULL);
        EXPECT(PALPATE_STATUS_OK, palpate_precomputed_loop_tick(&loop, &probe, 1, &force));
        palpate_table again = {{0}};
        CHECK(palpate_precomputed_table_load(&again, t.bytes, t.len, NULL) != PALPATE_STATUS_OK);
        t.bytes[at] ^= 0xA5;
    }
    free_table(&tm);
    free_table(&t);
}

static void test_precomputed_loop(const char *path) {
    table_file t = read_table(path, 0);
    palpate_table table = {{0}};
    EXPECT(PALPATE_STATUS_OK, palpate_precomputed_table_load(&table, t.bytes, t.len, NULL));
    palpate_precomputed_loop loop;
    memset(&loop, 0, sizeof loop);
    palpate_error error = {{0}};
    palpate_loop_config config = palpate_loop_config_default();
    CHECK(config.tool_points == 1 && config.radius_m == 0.002f && config.dt_s == 0.001f &&
          config.max_force_n == 4.0f && config.max_slew_n_per_s == 2000.0f);
    palpate_tool probe = {{0.012f, 0.013f, 0.0325f}, PALPATE_TOOL_ACTION_TOUCH, {0, 0, 0}};
    palpate_force force;
    static float u[VERTICES][3];

    /* Never created: every function refuses it. */
    EXPECT(PALPATE_STATUS_NOT_INITIALIZED, palpate_precomputed_loop_tick(&loop, &probe, 1, &force));
    EXPECT(PALPATE_STATUS_NOT_INITIALIZED, palpate_precomputed_loop_reset(&loop));
    EXPECT(PALPATE_STATUS_NOT_INITIALIZED, palpate_precomputed_loop_displacements(&loop, u, VERTICES, NULL));
    /* Bad configurations; each failure leaves the handle not initialized. */
    palpate_loop_config bad = config;
    bad.tool_points = 0;
    EXPECT(PALPATE_STATUS_BAD_ARGUMENT, palpate_precomputed_loop_create(&loop, &table, &bad, &error));
    bad.tool_points = PALPATE_TOOL_POINTS + 1;
    EXPECT(PALPATE_STATUS_BAD_ARGUMENT, palpate_precomputed_loop_create(&loop, &table, &bad, &error));
    bad = config;
    bad.radius_m = -1.0f;
    EXPECT(PALPATE_STATUS_LOOP_BAD_CONFIG, palpate_precomputed_loop_create(&loop, &table, &bad, &error));
    CHECK(strcmp(message(&error), "tool radius and haptic period must be finite and > 0") == 0);
    bad = config;
    bad.max_slew_n_per_s = INFINITY;
    EXPECT(PALPATE_STATUS_LOOP_BAD_LIMITS, palpate_precomputed_loop_create(&loop, &table, &bad, &error));
    CHECK(strcmp(message(&error), "safety limits must be finite and > 0") == 0);
    EXPECT(PALPATE_STATUS_NULL_POINTER, palpate_precomputed_loop_create(&loop, &table, NULL, NULL));
    EXPECT(PALPATE_STATUS_NULL_POINTER, palpate_precomputed_loop_create(&loop, NULL, &config, NULL));
    EXPECT(PALPATE_STATUS_NULL_POINTER, palpate_precomputed_loop_create(NULL, &table, &config, NULL));
    palpate_table never = {{0}};
    EXPECT(PALPATE_STATUS_NOT_INITIALIZED, palpate_precomputed_loop_create(&loop, &never, &config, NULL));
    EXPECT(PALPATE_STATUS_NOT_INITIALIZED, palpate_precomputed_loop_tick(&loop, &probe, 1, &force));

    EXPECT(PALPATE_STATUS_OK, palpate_precomputed_loop_create(&loop, &table, &config, &error));
    /* At rest: zero field. */
    EXPECT(PALPATE_STATUS_OK, palpate_precomputed_loop_displacements(&loop, u, VERTICES, NULL));
    CHECK(u[53][2] == 0.0f);
    /* Tick arguments. */
    EXPECT(PALPATE_STATUS_BAD_ARGUMENT, palpate_precomputed_loop_tick(&loop, &probe, 2, &force));
    EXPECT(PALPATE_STATUS_NULL_POINTER, palpate_precomputed_loop_tick(&loop, NULL, 1, &force));
    EXPECT(PALPATE_STATUS_NULL_POINTER, palpate_precomputed_loop_tick(&loop, &probe, 1, NULL));
    EXPECT(PALPATE_STATUS_NULL_POINTER, palpate_precomputed_loop_tick(NULL, &probe, 1, &force));
    palpate_tool odd = probe;
    odd.action = 9;
    EXPECT(PALPATE_STATUS_BAD_ARGUMENT, palpate_precomputed_loop_tick(&loop, &odd, 1, &force));

    /* Press 1.5 mm into the top face over 20 ticks: one contact, a force up
       (+z) that grows as the probe goes down. */
    float last = 0.0f;
    for (int t = 0; t < 20; t++) {
        probe.position_m[2] = 0.0325f - 0.0001f * (float)(t + 1);
        EXPECT(PALPATE_STATUS_OK, palpate_precomputed_loop_tick(&loop, &probe, 1, &force));
        CHECK(force.status == PALPATE_OUTPUT_STATUS_OK);
        CHECK(force.force_n[2] >= last);
        last = force.force_n[2];
    }
    CHECK(force.contacts == 1 && force.refused == 0 && !force.cut_refused && last > 0.05f);
    /* The field: the top face went down under the probe. */
    EXPECT(PALPATE_STATUS_OK, palpate_precomputed_loop_displacements(&loop, u, VERTICES, &error));
    CHECK(u[53][2] < -1e-4f && u[0][2] == 0.0f);
    EXPECT(PALPATE_STATUS_DISPLACEMENT_BUFFER, palpate_precomputed_loop_displacements(&loop, u, 3, &error));
    /* A blade on the pre-computed model: a probe, and says so. */
    palpate_tool blade = probe;
    blade.action = PALPATE_TOOL_ACTION_CUT;
    blade.blade_m[2] = -0.01f;
    EXPECT(PALPATE_STATUS_OK, palpate_precomputed_loop_tick(&loop, &blade, 1, &force));
    CHECK(force.cut_refused && force.contacts == 1);
    /* A non-finite position latches a fault: zero force until reset. */
    palpate_tool lost = probe;
    lost.position_m[0] = NAN;
    EXPECT(PALPATE_STATUS_OK, palpate_precomputed_loop_tick(&loop, &lost, 1, &force));
    CHECK(force.status == PALPATE_OUTPUT_STATUS_FAULT_NON_FINITE_INPUT && force.force_n[2] == 0.0f);
    EXPECT(PALPATE_STATUS_OK, palpate_precomputed_loop_tick(&loop, &probe, 1, &force));
    CHECK(force.status == PALPATE_OUTPUT_STATUS_FAULT_NON_FINITE_INPUT && force.force_n[2] == 0.0f);
    EXPECT(PALPATE_STATUS_OK, palpate_precomputed_loop_reset(&loop));
    EXPECT(PALPATE_STATUS_NULL_POINTER, palpate_precomputed_loop_reset(NULL));
    EXPECT(PALPATE_STATUS_OK, palpate_precomputed_loop_tick(&loop, &probe, 1, &force));
    CHECK(force.status == PALPATE_OUTPUT_STATUS_OK && force.contacts == 1 && force.force_n[2] > 0.0f);

    /* Two tool points: the second is in the same handle layout; both press. */
    palpate_loop_config two = config;
    two.tool_points = 2;
    EXPECT(PALPATE_STATUS_OK, palpate_precomputed_loop_create(&loop, &table, &two, NULL));
    palpate_tool probes[2] = {probe, probe};
    probes[1].position_m[0] = 0.018f;
    probes[0].position_m[2] = probes[1].position_m[2] = 0.0325f;
    EXPECT(PALPATE_STATUS_OK, palpate_precomputed_loop_tick(&loop, probes, 2, &force));
    probes[0].position_m[2] = probes[1].position_m[2] = 0.0315f;
    EXPECT(PALPATE_STATUS_OK, palpate_precomputed_loop_tick(&loop, probes, 2, &force));
    CHECK(force.contacts == 2 && force.force_n[2] > 0.0f);
    EXPECT(PALPATE_STATUS_BAD_ARGUMENT, palpate_precomputed_loop_tick(&loop, probes, 1, &force));

    /* A loop over a tensor-mass table is refused. */
    free_table(&t);
}

/* Physics for the box's tensor-mass tables: linear, symplectic Euler at
   0.5 ms (the box's critical step is 1.47 ms), 2 steps per update. */
static palpate_physics_config box_physics(void) {
    palpate_physics_config p = {
        .law = PALPATE_LAW_LINEAR,
        .incompressibility_n = 0.0f,
        .damping_per_s = 20.0f,
        .gravity_m_s2 = {0, 0, 0},
        .max_displacement_m = 0.01f,
        .max_kinetic_energy_j = INFINITY,
        .integrator = PALPATE_INTEGRATOR_SYMPLECTIC_EULER,
        .extrapolation = PALPATE_EXTRAPOLATION_SECANT,
        .dt_s = 0.0005f,
        .substeps = 2,
        .cut_capacity_tets = 8,
        .cut_force_n = 0.2f,
        .tear_capacity_tets = 0,
    };
    return p;
}

static void test_dynamic_loop(const char *path, const char *tensor_path) {
    table_file tm = read_table(tensor_path, 0);
    table_file pc = read_table(path, 0);
    palpate_table table = {{0}}, precomputed = {{0}};
    palpate_error error = {{0}};
    EXPECT(PALPATE_STATUS_OK, palpate_tensor_mass_table_load(&table, tm.bytes, tm.len, &error));
    EXPECT(PALPATE_STATUS_OK, palpate_precomputed_table_load(&precomputed, pc.bytes, pc.len, &error));
    palpate_physics_config physics = box_physics();
    palpate_loop_config config = palpate_loop_config_default();
    size_t bytes = 0, rk4_bytes = 0, terms_bytes = 0;

    /* Memory sizes: more for RK4 (4N vectors) and the split terms. */
    EXPECT(PALPATE_STATUS_OK, palpate_dynamic_memory_size(&table, &physics, &bytes));
    palpate_physics_config rk4 = physics;
    rk4.integrator = PALPATE_INTEGRATOR_RK4;
    EXPECT(PALPATE_STATUS_OK, palpate_dynamic_memory_size(&table, &rk4, &rk4_bytes));
    CHECK(rk4_bytes == bytes + 4 * VERTICES * 12);
    palpate_physics_config terms = physics;
    terms.law = PALPATE_LAW_STVK_TENSORS;
    EXPECT(PALPATE_STATUS_OK, palpate_dynamic_memory_size(&table, &terms, &terms_bytes));
    CHECK(terms_bytes > bytes);
    EXPECT(PALPATE_STATUS_WRONG_TABLE, palpate_dynamic_memory_size(&precomputed, &physics, &bytes));
    EXPECT(PALPATE_STATUS_NULL_POINTER, palpate_dynamic_memory_size(&table, NULL, &bytes));
    EXPECT(PALPATE_STATUS_NULL_POINTER, palpate_dynamic_memory_size(&table, &physics, NULL));
    EXPECT(PALPATE_STATUS_OK, palpate_dynamic_memory_size(&table, &physics, &bytes));

    palpate_dynamic_loop *loop = aligned_alloc(8, sizeof(palpate_dynamic_loop));
    memset(loop, 0, sizeof *loop);
    /* The block, exactly the size asked for (plus 8 to test misalignment). */
    unsigned char *memory = aligned_alloc(PALPATE_MEMORY_ALIGN, (bytes + 8 + 7) / 8 * 8);
    EXPECT(PALPATE_STATUS_MEMORY_TOO_SMALL, palpate_dynamic_loop_create(loop, &table, &config, &physics,
                                                                        memory, bytes - 1, &error));
    EXPECT(PALPATE_STATUS_NOT_INITIALIZED, palpate_dynamic_loop_reset(loop));
    EXPECT(PALPATE_STATUS_MISALIGNED, palpate_dynamic_loop_create(loop, &table, &config, &physics,
                                                                  memory + 4, bytes, &error));
    EXPECT(PALPATE_STATUS_NULL_POINTER,
           palpate_dynamic_loop_create(loop, &table, &config, &physics, NULL, bytes, &error));
    EXPECT(PALPATE_STATUS_WRONG_TABLE, palpate_dynamic_loop_create(loop, &precomputed, &config, &physics,
                                                                   memory, bytes, &error));
    /* Out-of-range physics: enums, then the kernel's checks. */
    palpate_physics_config bad = physics;
    bad.integrator = 4;
    EXPECT(PALPATE_STATUS_BAD_ARGUMENT,
           palpate_dynamic_loop_create(loop, &table, &config, &bad, memory, bytes, &error));
    bad = physics;
    bad.law = 5;
    EXPECT(PALPATE_STATUS_BAD_ARGUMENT,
           palpate_dynamic_loop_create(loop, &table, &config, &bad, memory, bytes, &error));
    bad = physics;
    bad.extrapolation = 2;
    EXPECT(PALPATE_STATUS_BAD_ARGUMENT,
           palpate_dynamic_loop_create(loop, &table, &config, &bad, memory, bytes, &error));
    bad = physics;
    bad.tear_capacity_tets = 4;
    bad.tear_max_elongation = -1.0f;
    EXPECT(PALPATE_STATUS_BAD_ARGUMENT,
           palpate_dynamic_loop_create(loop, &table, &config, &bad, memory, bytes, &error));
    bad = physics;
    bad.damping_per_s = -1.0f;
    EXPECT(PALPATE_STATUS_STATE_BAD_PARAMETER,
           palpate_dynamic_loop_create(loop, &table, &config, &bad, memory, bytes, &error));
    CHECK(strcmp(message(&error), "parameter damping_per_s must be finite and >= 0") == 0);
    bad = physics;
    bad.substeps = 0;
    EXPECT(PALPATE_STATUS_BAD_PHYSICS,
           palpate_dynamic_loop_create(loop, &table, &config, &bad, memory, bytes, &error));
    bad = physics;
    bad.cut_capacity_tets = 65;
    EXPECT(PALPATE_STATUS_BAD_PHYSICS,
           palpate_dynamic_loop_create(loop, &table, &config, &bad, memory, bytes, &error));
    palpate_loop_config bad_config = config;
    bad_config.dt_s = 0.0f;
    EXPECT(PALPATE_STATUS_LOOP_BAD_CONFIG,
           palpate_dynamic_loop_create(loop, &table, &bad_config, &physics, memory, bytes, &error));

    /* A probe and a blade (two tool points). */
    config.tool_points = 2;
    EXPECT(PALPATE_STATUS_OK,
           palpate_dynamic_loop_create(loop, &table, &config, &physics, memory, bytes, &error));
    palpate_tool tools[2] = {
        {{0.012f, 0.013f, 0.0325f}, PALPATE_TOOL_ACTION_TOUCH, {0, 0, 0}},
        {{0.025f, 0.025f, 0.0325f}, PALPATE_TOOL_ACTION_TOUCH, {0, 0, 0}},
    };
    palpate_force force;
    palpate_physics_report report;
    static float u[VERTICES][3];
    uint32_t removed[64];
    size_t count = 99;
    EXPECT(PALPATE_STATUS_OK, palpate_dynamic_loop_tick(loop, tools, 2, &force));
    for (int t = 0; t < 15; t++) {
        tools[0].position_m[2] = 0.0325f - 0.0001f * (float)(t + 1);
        EXPECT(PALPATE_STATUS_OK, palpate_dynamic_loop_tick(loop, tools, 2, &force));
        EXPECT(PALPATE_STATUS_OK, palpate_dynamic_loop_physics_update(loop, &report, &error));
    }
    CHECK(force.status == PALPATE_OUTPUT_STATUS_OK && force.contacts == 1 && force.force_n[2] > 0.0f);
    CHECK(report.removed_tets == 0 && report.force_evaluations == 1 && report.kinetic_energy_j >= 0.0f);
    EXPECT(PALPATE_STATUS_OK, palpate_dynamic_loop_displacements(loop, u, VERTICES, &error));
    CHECK(u[53][2] < 0.0f && u[0][2] == 0.0f);
    EXPECT(PALPATE_STATUS_DISPLACEMENT_BUFFER, palpate_dynamic_loop_displacements(loop, u, 1, &error));
    EXPECT(PALPATE_STATUS_NULL_POINTER, palpate_dynamic_loop_physics_update(NULL, &report, NULL));
    EXPECT(PALPATE_STATUS_OK, palpate_dynamic_loop_physics_update(loop, NULL, NULL));
    /* The blade goes down into the far corner and cuts at the next update. */
    tools[1].action = PALPATE_TOOL_ACTION_CUT;
    tools[1].blade_m[2] = -0.01f;
    tools[1].position_m[2] = 0.0295f;
    EXPECT(PALPATE_STATUS_OK, palpate_dynamic_loop_tick(loop, tools, 2, &force));
    EXPECT(PALPATE_STATUS_OK, palpate_dynamic_loop_physics_update(loop, &report, &error));
    CHECK(report.removed_tets > 0);
    EXPECT(PALPATE_STATUS_OK, palpate_dynamic_loop_removed_tets(loop, removed, 64, &count));
    CHECK(count == report.removed_tets && count > 0 && removed[0] < 162);
    if (count > 1) {
        EXPECT(PALPATE_STATUS_BAD_ARGUMENT, palpate_dynamic_loop_removed_tets(loop, removed, 1, &count));
        CHECK(count == report.removed_tets);
    }
    EXPECT(PALPATE_STATUS_NULL_POINTER, palpate_dynamic_loop_removed_tets(loop, removed, 64, NULL));
    EXPECT(PALPATE_STATUS_NULL_POINTER, palpate_dynamic_loop_removed_tets(loop, NULL, 64, &count));
    EXPECT(PALPATE_STATUS_OK, palpate_dynamic_loop_reset(loop));
    EXPECT(PALPATE_STATUS_OK, palpate_dynamic_loop_removed_tets(loop, NULL, 0, &count));
    CHECK(count == 0);
    EXPECT(PALPATE_STATUS_BAD_ARGUMENT, palpate_dynamic_loop_tick(loop, tools, 1, &force));

    /* Divergence: a displacement bound of 0.1 µm under gravity faults at the
       first update; the next tick latches a model fault; reset clears it. */
    palpate_physics_config fragile = physics;
    fragile.gravity_m_s2[2] = -9.81f;
    fragile.max_displacement_m = 1e-7f;
    config.tool_points = 1;
    EXPECT(PALPATE_STATUS_OK,
           palpate_dynamic_loop_create(loop, &table, &config, &fragile, memory, bytes, &error));
    palpate_tool probe = {{0.012f, 0.013f, 0.0315f}, PALPATE_TOOL_ACTION_TOUCH, {0, 0, 0}};
    EXPECT(PALPATE_STATUS_OK, palpate_dynamic_loop_tick(loop, &probe, 1, &force));
    EXPECT(PALPATE_STATUS_FAULT_DISPLACEMENT_BOUND, palpate_dynamic_loop_physics_update(loop, &report, &error));
    CHECK(strstr(message(&error), "displacement beyond the bound") != NULL);
    EXPECT(PALPATE_STATUS_OK, palpate_dynamic_loop_tick(loop, &probe, 1, &force));
    CHECK(force.status == PALPATE_OUTPUT_STATUS_FAULT_MODEL && force.force_n[2] == 0.0f);
    EXPECT(PALPATE_STATUS_FAULT_DISPLACEMENT_BOUND, palpate_dynamic_loop_displacements(loop, u, VERTICES, &error));
    EXPECT(PALPATE_STATUS_OK, palpate_dynamic_loop_reset(loop));
    EXPECT(PALPATE_STATUS_OK, palpate_dynamic_loop_displacements(loop, u, VERTICES, &error));

    /* Every law and integrator builds and steps over its own memory size. */
    const uint32_t laws[] = {PALPATE_LAW_LINEAR, PALPATE_LAW_STVK, PALPATE_LAW_STVK_TENSORS,
                             PALPATE_LAW_COROTATIONAL, PALPATE_LAW_NEO_HOOKEAN};
    const uint32_t integrators[] = {PALPATE_INTEGRATOR_EXPLICIT_EULER, PALPATE_INTEGRATOR_SYMPLECTIC_EULER,
                                    PALPATE_INTEGRATOR_RK4, PALPATE_INTEGRATOR_CENTRAL_DIFFERENCE};
    for (size_t l = 0; l < 5; l++) {
        for (size_t i = 0; i < 4; i++) {
            palpate_physics_config p = physics;
            p.law = laws[l];
            p.integrator = integrators[i];
            p.dt_s = 2e-5f; /* below explicit Euler's limit too */
            p.incompressibility_n = l == 1 ? 0.01f : 0.0f;
            size_t need = 0;
            EXPECT(PALPATE_STATUS_OK, palpate_dynamic_memory_size(&table, &p, &need));
            unsigned char *block = aligned_alloc(8, (need + 7) / 8 * 8);
            palpate_dynamic_loop *each = aligned_alloc(8, sizeof *each);
            EXPECT(PALPATE_STATUS_OK, palpate_dynamic_loop_create(each, &table, &config, &p, block, need, &error));
            EXPECT(PALPATE_STATUS_OK, palpate_dynamic_loop_tick(each, &probe, 1, &force));
            EXPECT(PALPATE_STATUS_OK, palpate_dynamic_loop_physics_update(each, &report, &error));
            CHECK(report.force_evaluations == (p.integrator == PALPATE_INTEGRATOR_RK4 ? 4u : 1u));
            free(each);
            free(block);
        }
    }
    free(memory);
    free(loop);
    free_table(&pc);
    free_table(&tm);
}

static void test_hybrid_loop(const char *dir, const char *tensor_path) {
    char path[4096];
    snprintf(path, sizeof path, "%s/precomputed.bin", dir);
    table_file pc = read_table(path, 0);
    snprintf(path, sizeof path, "%s/dynamic.bin", dir);
    table_file dy = read_table(path, 0);
    snprintf(path, sizeof path, "%s/interface.bin", dir);
    table_file in = read_table(path, 0);
    table_file box = read_table(tensor_path, 0);
    palpate_table precomputed = {{0}}, dynamic = {{0}}, interface = {{0}}, other = {{0}};
    palpate_error error = {{0}};
    palpate_table_info info;
    EXPECT(PALPATE_STATUS_OK, palpate_precomputed_table_load(&precomputed, pc.bytes, pc.len, &error));
    EXPECT(PALPATE_STATUS_OK, palpate_tensor_mass_table_load(&dynamic, dy.bytes, dy.len, &error));
    EXPECT(PALPATE_STATUS_OK, palpate_interface_table_load(&interface, in.bytes, in.len, &error));
    EXPECT(PALPATE_STATUS_OK, palpate_tensor_mass_table_load(&other, box.bytes, box.len, &error));
    EXPECT(PALPATE_STATUS_OK, palpate_table_get_info(&interface, &info));
    CHECK(info.kind == PALPATE_TABLE_KIND_INTERFACE && info.vertex_count == VERTICES &&
          info.connection_count == 7);
    palpate_physics_config physics = box_physics();
    palpate_loop_config config = palpate_loop_config_default();
    size_t bytes = 0;
    EXPECT(PALPATE_STATUS_OK, palpate_hybrid_memory_size(&precomputed, &dynamic, &interface, &physics, &bytes));
    EXPECT(PALPATE_STATUS_WRONG_TABLE,
           palpate_hybrid_memory_size(&dynamic, &precomputed, &interface, &physics, &bytes));
    EXPECT(PALPATE_STATUS_NULL_POINTER,
           palpate_hybrid_memory_size(&precomputed, &dynamic, NULL, &physics, &bytes));
    unsigned char *memory = aligned_alloc(PALPATE_MEMORY_ALIGN, (bytes + 7) / 8 * 8);
    palpate_hybrid_loop *loop = aligned_alloc(8, sizeof(palpate_hybrid_loop));
    memset(loop, 0, sizeof *loop);
    EXPECT(PALPATE_STATUS_NOT_INITIALIZED, palpate_hybrid_loop_reset(loop));
    EXPECT(PALPATE_STATUS_MEMORY_TOO_SMALL, palpate_hybrid_loop_create(loop, &precomputed, &dynamic, &interface,
                                                                       &config, &physics, memory, bytes / 2, &error));
    /* Another build's tensor-mass table (the whole box's): the three do not
       belong together. */
    size_t other_bytes = 0;
    EXPECT(PALPATE_STATUS_OK, palpate_hybrid_memory_size(&precomputed, &other, &interface, &physics, &other_bytes));
    unsigned char *other_memory = aligned_alloc(8, (other_bytes + 7) / 8 * 8);
    EXPECT(PALPATE_STATUS_HYBRID_MISMATCH, palpate_hybrid_loop_create(loop, &precomputed, &other, &interface,
                                                                      &config, &physics, other_memory,
                                                                      other_bytes, &error));
    CHECK(strstr(message(&error), "does not belong with the region tables") != NULL);
    free(other_memory);
    EXPECT(PALPATE_STATUS_OK, palpate_hybrid_loop_create(loop, &precomputed, &dynamic, &interface, &config,
                                                         &physics, memory, bytes, &error));
    /* Press the pre-computed region (vertex 53's corner of the top face) and
       the tensor-mass corner cell (x, y > 0.02) in turn. */
    palpate_tool probe = {{0.012f, 0.013f, 0.0325f}, PALPATE_TOOL_ACTION_TOUCH, {0, 0, 0}};
    palpate_force force;
    palpate_physics_report report;
    static float u[VERTICES][3];
    for (int t = 0; t < 15; t++) {
        probe.position_m[2] = 0.0325f - 0.0001f * (float)(t + 1);
        EXPECT(PALPATE_STATUS_OK, palpate_hybrid_loop_tick(loop, &probe, 1, &force));
        EXPECT(PALPATE_STATUS_OK, palpate_hybrid_loop_physics_update(loop, &report, &error));
    }
    CHECK(force.status == PALPATE_OUTPUT_STATUS_OK && force.contacts == 1 && force.force_n[2] > 0.0f);
    EXPECT(PALPATE_STATUS_OK, palpate_hybrid_loop_displacements(loop, u, VERTICES, &error));
    CHECK(u[53][2] < 0.0f && u[0][2] == 0.0f);
    EXPECT(PALPATE_STATUS_DISPLACEMENT_BUFFER, palpate_hybrid_loop_displacements(loop, u, 2, &error));
    EXPECT(PALPATE_STATUS_OK, palpate_hybrid_loop_reset(loop));
    probe.position_m[0] = probe.position_m[1] = 0.025f;
    for (int t = 0; t < 15; t++) {
        probe.position_m[2] = 0.0325f - 0.0001f * (float)(t + 1);
        EXPECT(PALPATE_STATUS_OK, palpate_hybrid_loop_tick(loop, &probe, 1, &force));
        EXPECT(PALPATE_STATUS_OK, palpate_hybrid_loop_physics_update(loop, &report, &error));
    }
    CHECK(force.status == PALPATE_OUTPUT_STATUS_OK && force.contacts == 1 && force.force_n[2] > 0.0f);
    EXPECT(PALPATE_STATUS_OK, palpate_hybrid_loop_displacements(loop, u, VERTICES, &error));
    CHECK(u[63][2] < 0.0f);
    size_t count = 99;
    EXPECT(PALPATE_STATUS_OK, palpate_hybrid_loop_removed_tets(loop, NULL, 0, &count));
    CHECK(count == 0);
    EXPECT(PALPATE_STATUS_NULL_POINTER, palpate_hybrid_loop_tick(loop, NULL, 1, &force));
    EXPECT(PALPATE_STATUS_NULL_POINTER, palpate_hybrid_loop_physics_update(NULL, NULL, NULL));
    free(loop);
    free(memory);
    free_table(&box);
    free_table(&in);
    free_table(&dy);
    free_table(&pc);
}

int main(int argc, char **argv) {
    if (argc != 5) {
        fprintf(stderr, "usage: %s TABLE TENSOR_TABLE HYBRID_DIR HOST_REPLAY\n", argv[0]);
        return 2;
    }
    test_versions_and_messages();
    test_tables(argv[1], argv[2], argv[4]);
    test_precomputed_loop(argv[1]);
    test_dynamic_loop(argv[1], argv[2]);
    test_hybrid_loop(argv[3], argv[2]);
    printf("abi_test: %d checks, %d failed\n", checks, failures);
    return failures == 0 ? 0 : 1;
}

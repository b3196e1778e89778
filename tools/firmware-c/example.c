/*
 * The C example's portable part (example.h): the scripted replay and a
 * haptic loop, through the C ABI only, printing every float as its f32 bit
 * pattern so that the Cortex-M4F and the host can be compared byte for byte.
 * No allocation, no stdio: output goes through example_write.
 */
#include "example.h"

#include <string.h>

#include "sequence.h"

/* Output helpers: text, decimal, an f32's bit pattern as 0x%08x (what the
   Rust replay prints with {:#010x} of f32::to_bits). */
static void put(const char *text) { example_write(text, strlen(text)); }

static void put_u32(uint32_t value) {
    char digits[10];
    size_t n = 0;
    do {
        digits[sizeof digits - 1 - n++] = (char)('0' + value % 10);
        value /= 10;
    } while (value != 0);
    example_write(digits + sizeof digits - n, n);
}

static void put_bits(float value) {
    static const char hex[] = "0123456789abcdef";
    char text[10] = {'0', 'x'};
    uint32_t bits;
    memcpy(&bits, &value, sizeof bits);
    for (int i = 0; i < 8; i++) {
        text[2 + i] = hex[(bits >> (28 - 4 * i)) & 0xf];
    }
    example_write(text, sizeof text);
}

static void put_vector(const float v[3]) {
    for (int i = 0; i < 3; i++) {
        put(" ");
        put_bits(v[i]);
    }
}

/* `# <what>: <status message>: <details>` for a failed call. */
static int failed(const char *what, palpate_status status, const palpate_error *error) {
    char details[160];
    put("# ");
    put(what);
    put(": ");
    put(palpate_status_message(status));
    if (error != NULL && palpate_error_message(error, details, sizeof details) > 0) {
        put(": ");
        put(details);
    }
    put("\n");
    return 1;
}

/* Displacements of every vertex, m (static: .bss). */
static float displacements_m[EXAMPLE_VERTICES][3];

/* The largest absolute displacement component of the first `n` vertices,
   as the Rust replay folds it (`max` from 0, which skips a NaN). */
static float largest(size_t n) {
    float m = 0.0f;
    for (size_t v = 0; v < n; v++) {
        for (int i = 0; i < 3; i++) {
            float u = displacements_m[v][i] < 0.0f ? -displacements_m[v][i] : displacements_m[v][i];
            if (u > m) {
                m = u;
            }
        }
    }
    return m;
}

/* The scripted sequence, as `palpate precomputed replay` prints it. */
static int replay(const palpate_table *table, size_t vertices) {
    for (uint32_t i = 0; i < SEQUENCE_STEPS; i++) {
        palpate_solution solution;
        palpate_error error = {{0}};
        example_wait_tick();
        put("step ");
        put_u32(i);
        palpate_status status = palpate_precomputed_solve(
            table, SEQUENCE[i].contacts, SEQUENCE[i].count, &solution, &error);
        if (status != PALPATE_STATUS_OK) {
            char message[160];
            palpate_error_message(&error, message, sizeof message);
            put(" error ");
            put(message);
            put("\n");
            continue;
        }
        put(" device");
        put_vector(solution.device_force_n);
        put(" contacts");
        for (uint32_t c = 0; c < solution.count; c++) {
            put_vector(solution.contact_forces_n[c]);
        }
        status = palpate_precomputed_displacements(table, &solution, displacements_m, vertices,
                                                   &error);
        if (status != PALPATE_STATUS_OK) {
            return failed("displacements", status, &error);
        }
        put(" umax ");
        put_bits(largest(vertices));
        put("\n");
    }
    return 0;
}

/* The haptic loop's scripted probe (m): radius 2 mm, above vertex 53 of the
   box's top face (z = 0.03 m), 0.5 mm clear of it. */
#define PROBE_RADIUS_M 0.002f
#define PROBE_X_M 0.012f
#define PROBE_Y_M 0.013f
#define PROBE_Z0_M (0.03f + PROBE_RADIUS_M + 0.0005f)
#define TICKS 45

/* Where the probe is at tick `t`: down 0.1 mm per tick for 20 ticks (1.5 mm
   into the surface), holds 5, slides +x 0.2 mm per tick for 10, a
   non-finite position at tick 35 and 36 (a latched fault; reset after 36),
   stays, then lifts 1 mm per tick from tick 40. */
static void probe_at(int t, float position_m[3]) {
    int down = t < 20 ? t + 1 : 20;
    int slide = t < 25 ? 0 : (t < 35 ? t - 24 : 10);
    int lift = t < 40 ? 0 : t - 39;
    position_m[0] = PROBE_X_M + 0.0002f * (float)slide;
    position_m[1] = PROBE_Y_M;
    position_m[2] = PROBE_Z0_M - 0.0001f * (float)down + 0.001f * (float)lift;
    if (t == 35 || t == 36) {
        position_m[0] = __builtin_nanf("");
    }
}

static int haptic(const palpate_table *table, size_t vertices) {
    static palpate_precomputed_loop loop; /* static: zero-initialized */
    palpate_error error = {{0}};
    palpate_loop_config config = palpate_loop_config_default();
    config.radius_m = PROBE_RADIUS_M;
    palpate_status status = palpate_precomputed_loop_create(&loop, table, &config, &error);
    if (status != PALPATE_STATUS_OK) {
        return failed("loop", status, &error);
    }
    for (int t = 0; t < TICKS; t++) {
        palpate_tool tool = {{0.0f, 0.0f, 0.0f}, PALPATE_TOOL_ACTION_TOUCH, {0.0f, 0.0f, 0.0f}};
        palpate_force force;
        example_wait_tick();
        probe_at(t, tool.position_m);
        status = palpate_precomputed_loop_tick(&loop, &tool, 1, &force);
        if (status != PALPATE_STATUS_OK) {
            return failed("tick", status, NULL);
        }
        put("tick ");
        put_u32((uint32_t)t);
        put(" force");
        put_vector(force.force_n);
        put(" status ");
        put_u32(force.status);
        put(" contacts ");
        put_u32(force.contacts);
        put(" refused ");
        put_u32(force.refused);
        put("\n");
        if (t == 24) {
            status = palpate_precomputed_loop_displacements(&loop, displacements_m, vertices,
                                                            &error);
            if (status != PALPATE_STATUS_OK) {
                return failed("field", status, &error);
            }
            put("field ");
            put_u32((uint32_t)t);
            put(" umax ");
            put_bits(largest(vertices));
            put("\n");
        }
        if (t == 36 && (status = palpate_precomputed_loop_reset(&loop)) != PALPATE_STATUS_OK) {
            return failed("reset", status, NULL);
        }
    }
    return 0;
}

int example_run(const uint8_t *bytes, size_t len) {
    static palpate_table table; /* static: zero-initialized */
    palpate_error error = {{0}};
    palpate_table_info info;
    if (palpate_abi_version() != PALPATE_ABI_VERSION) {
        put("# the library's ABI version differs from palpate.h's\n");
        return 1;
    }
    palpate_status status = palpate_precomputed_table_load(&table, bytes, len, &error);
    if (status != PALPATE_STATUS_OK) {
        return failed("table", status, &error);
    }
    if ((status = palpate_table_get_info(&table, &info)) != PALPATE_STATUS_OK) {
        return failed("table info", status, NULL);
    }
    if (info.vertex_count > EXAMPLE_VERTICES) {
        put("# the table has more vertices than EXAMPLE_VERTICES\n");
        return 1;
    }
    put("# table: ");
    put_u32((uint32_t)len);
    put(" bytes, ");
    put_u32(info.vertex_count);
    put(" vertices, ");
    put_u32(info.touchable_count);
    put(" touchable; handles: table ");
    put_u32((uint32_t)sizeof(palpate_table));
    put(" B, loop ");
    put_u32((uint32_t)sizeof(palpate_precomputed_loop));
    put(" B, solution ");
    put_u32((uint32_t)sizeof(palpate_solution));
    put(" B\n");
    return replay(&table, info.vertex_count) || haptic(&table, info.vertex_count);
}

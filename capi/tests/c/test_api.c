/*
 * The C API from C: misuse cases, then the built-in scene searched through the API.
 *
 * Built and run by ci/c_api.sh: with the system cc against the host static library, and with
 * arm-none-eabi-gcc for the Cortex-M4F (run under QEMU through semihosting, see startup_m4.c).
 * Portable C11 and printf only. The built-in scene (testkit/data/builtin_scene.bin,
 * format in testkit/src/scene_file.rs: a 56-byte little-endian header, then the
 * depth image as u16) is embedded with the assembler's .incbin: SCENE_FILE is its path, as a
 * string literal, e.g. -DSCENE_FILE='"/path/builtin_scene.bin"'.
 *
 * Prints "checks: N passed, M failed" last; exits 0 when nothing failed.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "shape_from_symmetry.h"

#ifndef SCENE_FILE
#error "define SCENE_FILE as the path of builtin_scene.bin, a string literal"
#endif

/* The scene file, in read-only data, 8-byte aligned (so the depth at offset 56 is aligned). */
__asm__(".section .rodata\n"
        ".balign 8\n"
        "scene_file:\n"
        ".incbin \"" SCENE_FILE "\"\n"
        "scene_file_end:\n"
        ".balign 8\n"
        ".previous\n");
extern const unsigned char scene_file[];
extern const unsigned char scene_file_end[];

#define HEADER_BYTES 56
#define OUTPUT_POINTS 3072

/* Engine storage, as a firmware would declare it: static (zeroed), size and alignment known at
 * compile time. A second buffer is never initialised (the "uninitialised handle" case). */
static _Alignas(SFS_ENGINE_STORAGE_ALIGN) unsigned char storage[SFS_ENGINE_STORAGE_BYTES];
static _Alignas(SFS_ENGINE_STORAGE_ALIGN) unsigned char never_initialised[SFS_ENGINE_STORAGE_BYTES];
static SfsPoint output[OUTPUT_POINTS];

static unsigned passed, failed;

#define CHECK(cond)                                                                      \
    do {                                                                                 \
        if (cond) {                                                                      \
            passed++;                                                                    \
        } else {                                                                         \
            failed++;                                                                    \
            printf("FAILED %s:%d: %s\n", __FILE__, __LINE__, #cond);                     \
        }                                                                                \
    } while (0)

/* A status check that prints both names on failure. */
#define CHECK_STATUS(call, expected)                                                     \
    do {                                                                                 \
        SfsStatus got_ = (call);                                                         \
        if (got_ == (expected)) {                                                        \
            passed++;                                                                    \
        } else {                                                                         \
            failed++;                                                                    \
            printf("FAILED %s:%d: %s -> %s, expected %s\n", __FILE__, __LINE__, #call,   \
                   sfs_status_name(got_), sfs_status_name(expected));                    \
        }                                                                                \
    } while (0)

static uint16_t u16_at(size_t i) {
    return (uint16_t)(scene_file[i] | (scene_file[i + 1] << 8));
}

static uint32_t u32_at(size_t i) {
    return (uint32_t)scene_file[i] | (uint32_t)scene_file[i + 1] << 8 |
           (uint32_t)scene_file[i + 2] << 16 | (uint32_t)scene_file[i + 3] << 24;
}

static float f32_at(size_t i) {
    uint32_t bits = u32_at(i);
    float f;
    memcpy(&f, &bits, sizeof f);
    return f;
}

/* The built-in scene as an SfsScene: its camera and table plane, no mask, our output. */
static SfsScene builtin_scene(void) {
    SfsScene s;
    memset(&s, 0, sizeof s);
    s.width = u16_at(12);
    s.height = u16_at(14);
    s.fx = f32_at(16);
    s.fy = f32_at(20);
    s.cx = f32_at(24);
    s.cy = f32_at(28);
    s.depth_scale = f32_at(32);
    s.has_table = u32_at(36);
    for (int i = 0; i < 3; i++) {
        s.table_normal[i] = f32_at(40 + 4 * (size_t)i);
    }
    s.table_offset = f32_at(52);
    /* Little-endian u16 on both hosts this runs on (x86-64, Cortex-M4F). */
    s.depth = (const uint16_t *)(const void *)(scene_file + HEADER_BYTES);
    s.depth_len = (size_t)s.width * s.height;
    s.mask = NULL;
    s.mask_len = 0;
    s.output = output;
    s.output_capacity = OUTPUT_POINTS;
    return s;
}

static void test_layout(void) {
    CHECK(memcmp(scene_file, "SFSDEPTH", 8) == 0 && u32_at(8) == 1);
    CHECK((size_t)(scene_file_end - scene_file) ==
          HEADER_BYTES + 2 * (size_t)u16_at(12) * u16_at(14));
    CHECK(sfs_engine_size() > 0 && sfs_engine_size() <= SFS_ENGINE_STORAGE_BYTES);
    CHECK(sfs_engine_align() > 0 && sfs_engine_align() <= SFS_ENGINE_STORAGE_ALIGN);
    CHECK((sfs_engine_align() & (sfs_engine_align() - 1)) == 0);
    CHECK(sizeof(SfsPoint) == 20);
    CHECK(sizeof(SfsStatus) == 4);
    CHECK(strcmp(sfs_status_name(SFS_STATUS_DONE), "done") == 0);
    CHECK(strcmp(sfs_status_name(SFS_STATUS_ERR_BAD_HANDLE), "err_bad_handle") == 0);
    CHECK(strcmp(sfs_status_name(42), "unknown") == 0);
    CHECK(strcmp(sfs_status_name(SFS_STATUS_ERR_TARGET_OUTSIDE_IMAGE),
                 "err_target_outside_image") == 0);
    CHECK(strcmp(sfs_status_name(SFS_STATUS_ERR_TARGET_ON_NO_OBJECT),
                 "err_target_on_no_object") == 0);
    CHECK(strcmp(sfs_status_name(SFS_STATUS_ERR_UNKNOWN_TARGET_KIND),
                 "err_unknown_target_kind") == 0);
    CHECK(strcmp(sfs_symmetry_type_name(SFS_SYMMETRY_TYPE_AXIAL_PLANE), "axial_plane") == 0);
}

static void test_init_misuse(void) {
    SfsEngine *engine = NULL;
    CHECK_STATUS(sfs_init(NULL, sizeof storage, &engine), SFS_STATUS_ERR_NULL_POINTER);
    CHECK_STATUS(sfs_init(storage, sizeof storage, NULL), SFS_STATUS_ERR_NULL_POINTER);
    CHECK_STATUS(sfs_init(storage, sfs_engine_size() - 1, &engine), SFS_STATUS_ERR_TOO_SMALL);
    CHECK_STATUS(sfs_init(storage, 0, &engine), SFS_STATUS_ERR_TOO_SMALL);
    CHECK_STATUS(sfs_init(storage + 1, sizeof storage - 1, &engine),
                 SFS_STATUS_ERR_BAD_ALIGNMENT);
    CHECK_STATUS(sfs_init(storage, sizeof storage, (SfsEngine **)(void *)storage),
                 SFS_STATUS_ERR_OVERLAP);
    CHECK(engine == NULL);
}

static void test_handle_misuse(void) {
    SfsScene scene = builtin_scene();
    SfsResult result;
    SfsSymmetry symmetry;
    SfsEngine *handles[3] = {
        NULL,
        (SfsEngine *)(void *)(storage + 4),        /* misaligned */
        (SfsEngine *)(void *)never_initialised,    /* zeroed, never initialised */
    };
    SfsStatus expected[3] = {SFS_STATUS_ERR_NULL_POINTER, SFS_STATUS_ERR_BAD_ALIGNMENT,
                             SFS_STATUS_ERR_BAD_HANDLE};
    for (int i = 0; i < 3; i++) {
        CHECK_STATUS(sfs_poll(handles[i], SFS_RECOMMENDED_BUDGET), expected[i]);
        CHECK_STATUS(sfs_set_input(handles[i], &scene), expected[i]);
        CHECK_STATUS(sfs_result(handles[i], &result), expected[i]);
        CHECK_STATUS(sfs_symmetry(handles[i], 0, &symmetry), expected[i]);
        CHECK_STATUS(sfs_runner_up(handles[i], &symmetry), expected[i]);
        CHECK_STATUS(sfs_config_types(handles[i], SFS_TYPES_ALL), expected[i]);
        CHECK_STATUS(sfs_config_parts(handles[i], 1), expected[i]);
        CHECK_STATUS(sfs_config_one_object(handles[i], 1), expected[i]);
        CHECK(sfs_points_written(handles[i]) == 0);
    }
}

static SfsEngine *init_engine(void) {
    SfsEngine *engine = NULL;
    CHECK_STATUS(sfs_init(storage, sizeof storage, &engine), SFS_STATUS_OK);
    CHECK(engine == (SfsEngine *)(void *)storage);
    return engine;
}

static void test_before_input(SfsEngine *engine) {
    SfsResult result;
    SfsSymmetry symmetry;
    CHECK_STATUS(sfs_poll(engine, SFS_RECOMMENDED_BUDGET), SFS_STATUS_ERR_NOT_STARTED);
    CHECK_STATUS(sfs_result(engine, &result), SFS_STATUS_OK);
    CHECK(result.state == SFS_STATUS_ERR_NOT_STARTED);
    CHECK(result.symmetries == 0 && result.polls == 0 && result.work_units == 0);
    CHECK(result.segmented == 0 && result.candidates == 0 && result.chosen == -1);
    CHECK_STATUS(sfs_symmetry(engine, 0, &symmetry), SFS_STATUS_ERR_OUT_OF_RANGE);
    CHECK_STATUS(sfs_runner_up(engine, &symmetry), SFS_STATUS_ERR_OUT_OF_RANGE);
    CHECK_STATUS(sfs_result(engine, NULL), SFS_STATUS_ERR_NULL_POINTER);
    CHECK_STATUS(sfs_symmetry(engine, 0, NULL), SFS_STATUS_ERR_NULL_POINTER);
    CHECK_STATUS(sfs_runner_up(engine, NULL), SFS_STATUS_ERR_NULL_POINTER);
    CHECK_STATUS(sfs_result(engine, (SfsResult *)(void *)(storage + 64)), SFS_STATUS_ERR_OVERLAP);
    CHECK(sfs_points_written(engine) == 0);
    CHECK_STATUS(sfs_config_types(engine, 0), SFS_STATUS_ERR_INVALID_CONFIG);
    CHECK_STATUS(sfs_config_types(engine, 1u << 8), SFS_STATUS_ERR_INVALID_CONFIG);
    CHECK_STATUS(sfs_config_parts(engine, 2), SFS_STATUS_ERR_INVALID_CONFIG);
    CHECK_STATUS(sfs_config_one_object(engine, 2), SFS_STATUS_ERR_INVALID_CONFIG);
}

static void test_input_misuse(SfsEngine *engine) {
    static uint8_t mask[8];
    const SfsScene good = builtin_scene();
    SfsScene s;

    CHECK_STATUS(sfs_set_input(engine, NULL), SFS_STATUS_ERR_NULL_POINTER);

    s = good; s.depth = NULL;
    CHECK_STATUS(sfs_set_input(engine, &s), SFS_STATUS_ERR_NULL_POINTER);
    s = good; s.depth = (const uint16_t *)(const void *)((const char *)good.depth + 1);
    CHECK_STATUS(sfs_set_input(engine, &s), SFS_STATUS_ERR_BAD_ALIGNMENT);
    s = good; s.depth_len = good.depth_len - 1;
    CHECK_STATUS(sfs_set_input(engine, &s), SFS_STATUS_ERR_DEPTH_SIZE_MISMATCH);
    s = good; s.depth_len = SIZE_MAX / 2;
    CHECK_STATUS(sfs_set_input(engine, &s), SFS_STATUS_ERR_TOO_LARGE);
    s = good; s.mask = mask; s.mask_len = sizeof mask;
    CHECK_STATUS(sfs_set_input(engine, &s), SFS_STATUS_ERR_MASK_SIZE_MISMATCH);
    s = good; s.mask = NULL; s.mask_len = good.depth_len;
    CHECK_STATUS(sfs_set_input(engine, &s), SFS_STATUS_ERR_NULL_POINTER);
    s = good; s.width = 70000;
    CHECK_STATUS(sfs_set_input(engine, &s), SFS_STATUS_ERR_TOO_LARGE);
    s = good; s.width = 0; s.depth_len = 0;
    CHECK_STATUS(sfs_set_input(engine, &s), SFS_STATUS_ERR_EMPTY_IMAGE);
    s = good; s.width = good.width + 1;
    CHECK_STATUS(sfs_set_input(engine, &s), SFS_STATUS_ERR_DEPTH_SIZE_MISMATCH);
    s = good; s.fx = -1.0f;
    CHECK_STATUS(sfs_set_input(engine, &s), SFS_STATUS_ERR_INVALID_INTRINSICS);
    s = good; s.depth_scale = 0.0f;
    CHECK_STATUS(sfs_set_input(engine, &s), SFS_STATUS_ERR_INVALID_DEPTH_SCALE);
    s = good; s.table_normal[2] += 1.0f;
    CHECK_STATUS(sfs_set_input(engine, &s), SFS_STATUS_ERR_INVALID_TABLE_PLANE);
    s = good; s.output = NULL;
    CHECK_STATUS(sfs_set_input(engine, &s), SFS_STATUS_ERR_NULL_POINTER);
    s = good; s.output = (SfsPoint *)(void *)((char *)output + 2);
    CHECK_STATUS(sfs_set_input(engine, &s), SFS_STATUS_ERR_BAD_ALIGNMENT);
    s = good; s.output = (SfsPoint *)(void *)storage; s.output_capacity = 4;
    CHECK_STATUS(sfs_set_input(engine, &s), SFS_STATUS_ERR_OVERLAP);
    s = good; s.output = (SfsPoint *)(void *)(uintptr_t)good.depth; s.output_capacity = 4;
    CHECK_STATUS(sfs_set_input(engine, &s), SFS_STATUS_ERR_OVERLAP);
    /* Targets: an unknown kind; a pixel or a region outside the image (beyond 16 bits too). */
    s = good; s.target_kind = 3;
    CHECK_STATUS(sfs_set_input(engine, &s), SFS_STATUS_ERR_UNKNOWN_TARGET_KIND);
    s = good; s.target_kind = SFS_TARGET_PIXEL; s.target_u = good.width; s.target_v = 0;
    CHECK_STATUS(sfs_set_input(engine, &s), SFS_STATUS_ERR_TARGET_OUTSIDE_IMAGE);
    s = good; s.target_kind = SFS_TARGET_PIXEL; s.target_u = 0; s.target_v = 70000;
    CHECK_STATUS(sfs_set_input(engine, &s), SFS_STATUS_ERR_TARGET_OUTSIDE_IMAGE);
    s = good; s.target_kind = SFS_TARGET_REGION; s.target_width = 0; s.target_height = 10;
    CHECK_STATUS(sfs_set_input(engine, &s), SFS_STATUS_ERR_TARGET_OUTSIDE_IMAGE);
    s = good; s.target_kind = SFS_TARGET_REGION; s.target_u = 10;
    s.target_width = good.width - 9; s.target_height = 10;
    CHECK_STATUS(sfs_set_input(engine, &s), SFS_STATUS_ERR_TARGET_OUTSIDE_IMAGE);
    s = good; s.target_kind = SFS_TARGET_REGION; s.target_width = 1; s.target_height = UINT32_MAX;
    CHECK_STATUS(sfs_set_input(engine, &s), SFS_STATUS_ERR_TARGET_OUTSIDE_IMAGE);

    /* Nothing was taken: still no input. */
    CHECK_STATUS(sfs_poll(engine, SFS_RECOMMENDED_BUDGET), SFS_STATUS_ERR_NOT_STARTED);
}

/* The digest of testkit/src/harness.rs (FNV-1a 64 over every bit of the result,
 * integers little-endian, floats as their bits), so that ci/c_api.sh can compare the search
 * through the C API with the Rust firmware example's, on the host and on the Cortex-M4F. */
static uint64_t fnv = 0xcbf29ce484222325ull;

static void h_u8(uint8_t v) {
    fnv = (fnv ^ v) * 0x00000100000001b3ull;
}

static void h_u32(uint32_t v) {
    for (int i = 0; i < 4; i++) {
        h_u8((uint8_t)(v >> (8 * i)));
    }
}

static void h_u64(uint64_t v) {
    h_u32((uint32_t)v);
    h_u32((uint32_t)(v >> 32));
}

static void h_f32s(const float *v, int n) {
    for (int i = 0; i < n; i++) {
        uint32_t bits;
        memcpy(&bits, &v[i], sizeof bits);
        h_u32(bits);
    }
}

static uint64_t digest(const SfsEngine *engine, const SfsResult *r) {
    fnv = 0xcbf29ce484222325ull;
    for (uint32_t i = 0; i < r->symmetries; i++) {
        SfsSymmetry s;
        if (sfs_symmetry(engine, i, &s) != SFS_STATUS_OK) {
            return 0;
        }
        h_u8((uint8_t)s.kind);
        h_f32s(&s.score, 1);
        h_u32(s.domain_points);
        /* Axis (direction, point) first, then planes (normal, offset), then the centre. */
        if (s.has_axis) {
            h_f32s(s.axis_direction, 3);
            h_f32s(s.axis_point, 3);
        }
        for (uint32_t k = 0; k < s.plane_count; k++) {
            h_f32s(s.planes[k].normal, 3);
            h_f32s(&s.planes[k].offset, 1);
        }
        if (s.has_centre) {
            h_f32s(s.centre, 3);
        }
    }
    size_t written = sfs_points_written(engine);
    for (size_t i = 0; i < written; i++) {
        h_f32s(output[i].position, 3);
        h_f32s(&output[i].plausibility, 1);
        h_u8(output[i].provenance);
        h_u8(output[i].symmetry);
    }
    h_u32(r->symmetries);
    h_u32(r->points_visible);
    h_u32(r->points_generated);
    h_u32(r->points_dropped);
    h_u32(r->object_pixels);
    h_u32(r->sampled_points);
    h_u64(r->work_units);
    h_u32(r->polls);
    return fnv;
}

/* Poll to the end with `budget`; returns the last status. Checks the best-so-far result
 * mid-search. */
static SfsStatus run(SfsEngine *engine, uint32_t budget) {
    SfsStatus status;
    uint32_t polls = 0;
    while ((status = sfs_poll(engine, budget)) == SFS_STATUS_WORKING) {
        if (++polls == 10) {
            SfsResult mid;
            CHECK_STATUS(sfs_result(engine, &mid), SFS_STATUS_OK);
            CHECK(mid.state == SFS_STATUS_WORKING && mid.polls == 10);
        }
        if (polls > 10000000u) {
            break;
        }
    }
    return status;
}

static SfsResult test_search(SfsEngine *engine) {
    SfsScene scene = builtin_scene();
    SfsResult result;
    SfsSymmetry sym;

    memset(output, 0xAB, sizeof output); /* any bytes: sfs_set_input clears the buffer */
    CHECK_STATUS(sfs_set_input(engine, &scene), SFS_STATUS_OK);
    memset(&scene, 0, sizeof scene); /* the description was copied */
    CHECK_STATUS(run(engine, SFS_RECOMMENDED_BUDGET), SFS_STATUS_DONE);
    CHECK_STATUS(sfs_poll(engine, SFS_RECOMMENDED_BUDGET), SFS_STATUS_DONE);

    CHECK_STATUS(sfs_result(engine, &result), SFS_STATUS_OK);
    CHECK(result.state == SFS_STATUS_DONE);
    CHECK(result.symmetries == 1);
    CHECK(result.points_visible > 500 && result.points_generated > 500);
    /* The default engine's voxel table fills on the built-in can (its axial + plane symmetry
     * predicts the whole surface): the points it cannot hold are counted, and what was written
     * fits the output. */
    CHECK(result.points_dropped > 0);
    CHECK(result.points_visible + result.points_generated <= OUTPUT_POINTS);
    CHECK(sfs_points_written(engine) == result.points_visible + result.points_generated);
    CHECK(result.work_units > 0 && result.polls > 1);
    CHECK(result.work_units <= (uint64_t)result.polls * SFS_RECOMMENDED_BUDGET);
    /* No mask: the engine segmented the object and chose one candidate. */
    CHECK(result.segmented == 1 && result.candidates >= 1);
    CHECK(result.chosen >= 0 && (uint32_t)result.chosen < result.candidates);
    CHECK(result.object_box[2] > 10 && result.object_box[3] > 10);
    CHECK(result.object_box[0] + result.object_box[2] <= u16_at(12) &&
          result.object_box[1] + result.object_box[3] <= u16_at(14));

    CHECK_STATUS(sfs_symmetry(engine, 0, &sym), SFS_STATUS_OK);
    CHECK(sym.kind == SFS_SYMMETRY_TYPE_AXIAL_PLANE);
    CHECK(sym.plane_count == 1 && sym.has_axis && !sym.has_centre);
    float d = sym.axis_direction[0] * sym.axis_direction[0] +
              sym.axis_direction[1] * sym.axis_direction[1] +
              sym.axis_direction[2] * sym.axis_direction[2];
    float n = sym.planes[0].normal[0] * sym.planes[0].normal[0] +
              sym.planes[0].normal[1] * sym.planes[0].normal[1] +
              sym.planes[0].normal[2] * sym.planes[0].normal[2];
    float along = sym.axis_direction[0] * sym.planes[0].normal[0] +
                  sym.axis_direction[1] * sym.planes[0].normal[1] +
                  sym.axis_direction[2] * sym.planes[0].normal[2];
    CHECK(fabsf(d - 1.0f) < 1e-3f && fabsf(n - 1.0f) < 1e-3f);
    CHECK(fabsf(fabsf(along) - 1.0f) < 1e-3f); /* the plane is orthogonal to the axis */
    CHECK(sym.score > 0.0f && sym.domain_points > 0);
    CHECK(sym.confidence > 0.0f && sym.confidence <= 1.0f);
    CHECK_STATUS(sfs_symmetry(engine, 1, &sym), SFS_STATUS_ERR_OUT_OF_RANGE);
    /* The runner-up: another hypothesis about the whole object (all its sampled points). */
    SfsSymmetry runner_up;
    CHECK_STATUS(sfs_runner_up(engine, &runner_up), SFS_STATUS_OK);
    CHECK(runner_up.confidence >= 0.0f && runner_up.confidence <= 1.0f);
    CHECK(runner_up.domain_points == result.sampled_points);

    size_t written = sfs_points_written(engine);
    CHECK(written == (size_t)result.points_visible + result.points_generated);
    CHECK(written > 1000 && written <= OUTPUT_POINTS);
    size_t visible = 0, generated = 0, bad = 0;
    for (size_t i = 0; i < written; i++) {
        const SfsPoint *p = &output[i];
        if (p->provenance == SFS_PROVENANCE_VISIBLE) {
            visible++;
            bad += generated != 0; /* visible points come first */
            bad += p->plausibility != 1.0f;
        } else if (p->provenance == SFS_PROVENANCE_GENERATED) {
            generated++;
            bad += p->symmetry != 0;
            bad += !(p->plausibility > 0.0f && p->plausibility <= 1.0f);
        } else {
            bad++;
        }
        bad += !(p->position[2] > 0.1f && p->position[2] < 2.0f); /* in front of the camera */
    }
    CHECK(bad == 0);
    CHECK(visible == result.points_visible && generated == result.points_generated);
    /* Cleared past the points where the output has room; a full output counts what it left out
     * (the can's completion needs more than the firmware's 3 072 points, whose digest this
     * test compares with). */
    CHECK(written == OUTPUT_POINTS ||
          (output[written].provenance == SFS_PROVENANCE_VISIBLE &&
           output[written].position[2] == 0.0f));
    CHECK(written < OUTPUT_POINTS || result.points_dropped > 0);

    printf("search: %s (score %.4f, %u domain points), %u visible + %u generated points, "
           "%llu work units in %u polls of %u\n",
           sfs_symmetry_type_name(sym.kind), (double)sym.score, (unsigned)sym.domain_points,
           (unsigned)result.points_visible, (unsigned)result.points_generated,
           (unsigned long long)result.work_units, (unsigned)result.polls,
           (unsigned)SFS_RECOMMENDED_BUDGET);
    /* The same line as the Rust firmware example prints (ci/c_api.sh compares them). */
    uint64_t dig = digest(engine, &result);
    printf("digest: 0x%08lx%08lx\n", (unsigned long)(dig >> 32), (unsigned long)(dig & 0xffffffffu));
    return result;
}

/* Poll until the engine has segmented the object or stopped; its result then. */
static SfsResult segment(SfsEngine *engine) {
    SfsResult r;
    memset(&r, 0, sizeof r);
    for (uint32_t polls = 0; polls < 100000u; polls++) {
        SfsStatus status = sfs_poll(engine, 5000);
        CHECK_STATUS(sfs_result(engine, &r), SFS_STATUS_OK);
        if (status != SFS_STATUS_WORKING || r.segmented) {
            break;
        }
    }
    return r;
}

/* A target on the can (its box's centre pixel, or its box as the region) chooses what the engine
 * chose alone (`plain`, the result of test_search); one on the table finds no object. */
static void test_targets(SfsEngine *engine, const SfsResult *plain) {
    const uint32_t *box = plain->object_box;
    SfsScene s = builtin_scene();
    SfsResult r;
    for (int region = 0; region < 2; region++) {
        s.target_kind = region ? SFS_TARGET_REGION : SFS_TARGET_PIXEL;
        s.target_u = region ? box[0] : box[0] + box[2] / 2;
        s.target_v = region ? box[1] : box[1] + box[3] / 2;
        s.target_width = box[2];
        s.target_height = box[3];
        CHECK_STATUS(sfs_set_input(engine, &s), SFS_STATUS_OK);
        r = segment(engine);
        CHECK(r.state == SFS_STATUS_WORKING && r.segmented == 1);
        CHECK(r.candidates == plain->candidates && r.chosen == plain->chosen);
        CHECK(memcmp(r.object_box, box, sizeof r.object_box) == 0);
    }
    s.target_kind = SFS_TARGET_PIXEL;
    s.target_u = 2;
    s.target_v = 2;
    CHECK_STATUS(sfs_set_input(engine, &s), SFS_STATUS_OK);
    CHECK_STATUS(run(engine, 5000), SFS_STATUS_ERR_TARGET_ON_NO_OBJECT);
    CHECK_STATUS(sfs_poll(engine, 5000), SFS_STATUS_ERR_TARGET_ON_NO_OBJECT);
    CHECK_STATUS(sfs_result(engine, &r), SFS_STATUS_OK);
    CHECK(r.state == SFS_STATUS_ERR_TARGET_ON_NO_OBJECT && r.segmented == 0 && r.chosen == -1);
}

/* A restricted search (plane reflection only) finds a plane; re-initialising forgets it. */
static void test_restricted_and_reinit(SfsEngine *engine) {
    SfsScene scene = builtin_scene();
    SfsResult result;
    SfsSymmetry sym;

    CHECK_STATUS(sfs_config_types(engine, 1u << SFS_SYMMETRY_TYPE_PLANE_REFLECTION),
                 SFS_STATUS_OK);
    CHECK_STATUS(sfs_poll(engine, 1), SFS_STATUS_ERR_NOT_STARTED); /* input discarded */
    CHECK(sfs_points_written(engine) == 0);
    CHECK_STATUS(sfs_set_input(engine, &scene), SFS_STATUS_OK);
    CHECK_STATUS(run(engine, 5000), SFS_STATUS_DONE);
    CHECK_STATUS(sfs_result(engine, &result), SFS_STATUS_OK);
    CHECK(result.symmetries == 1);
    CHECK_STATUS(sfs_symmetry(engine, 0, &sym), SFS_STATUS_OK);
    CHECK(sym.kind == SFS_SYMMETRY_TYPE_PLANE_REFLECTION && sym.plane_count == 1 &&
          !sym.has_axis);

    SfsEngine *again = init_engine();
    CHECK(again == engine);
    CHECK_STATUS(sfs_poll(again, 1), SFS_STATUS_ERR_NOT_STARTED);
    CHECK_STATUS(sfs_result(again, &result), SFS_STATUS_OK);
    CHECK(result.symmetries == 0 && result.state == SFS_STATUS_ERR_NOT_STARTED);
}

/* Part symmetries: every point names one of the symmetries found (or none, 255). */
static void test_parts(SfsEngine *engine) {
    SfsScene scene = builtin_scene();
    SfsResult result;
    CHECK_STATUS(sfs_config_parts(engine, 1), SFS_STATUS_OK);
    CHECK_STATUS(sfs_set_input(engine, &scene), SFS_STATUS_OK);
    CHECK_STATUS(run(engine, 5000), SFS_STATUS_DONE);
    CHECK_STATUS(sfs_result(engine, &result), SFS_STATUS_OK);
    CHECK(result.symmetries >= 1);
    size_t written = sfs_points_written(engine);
    CHECK(written > 0);
    size_t tagged = 0;
    for (size_t i = 0; i < written; i++) {
        CHECK(output[i].symmetry < result.symmetries || output[i].symmetry == 255);
        tagged += output[i].symmetry != 255;
    }
    CHECK(tagged > 0);
    CHECK_STATUS(sfs_config_parts(engine, 0), SFS_STATUS_OK);
}

/* One object in view: the built-in can stands alone, so nothing is parted from it and the
 * engine segments the same object and finds the same symmetry as by default. */
static void test_one_object(SfsEngine *engine, const SfsResult *plain) {
    SfsScene scene = builtin_scene();
    SfsResult result;
    SfsSymmetry sym;
    CHECK_STATUS(sfs_config_one_object(engine, 1), SFS_STATUS_OK);
    CHECK_STATUS(sfs_poll(engine, 1), SFS_STATUS_ERR_NOT_STARTED); /* input discarded */
    CHECK_STATUS(sfs_set_input(engine, &scene), SFS_STATUS_OK);
    CHECK_STATUS(run(engine, 5000), SFS_STATUS_DONE);
    CHECK_STATUS(sfs_result(engine, &result), SFS_STATUS_OK);
    CHECK(result.segmented == 1 && result.symmetries == plain->symmetries);
    CHECK(memcmp(result.object_box, plain->object_box, sizeof result.object_box) == 0);
    CHECK_STATUS(sfs_symmetry(engine, 0, &sym), SFS_STATUS_OK);
    CHECK(sym.kind == SFS_SYMMETRY_TYPE_AXIAL_PLANE);
    CHECK_STATUS(sfs_config_one_object(engine, 0), SFS_STATUS_OK);
}

int main(void) {
    test_layout();
    test_init_misuse();
    test_handle_misuse();
    SfsEngine *engine = init_engine();
    test_before_input(engine);
    test_input_misuse(engine);
    SfsResult plain = test_search(engine);
    test_targets(engine, &plain);
    test_restricted_and_reinit(engine);
    test_parts(init_engine());
    test_one_object(init_engine(), &plain);
    printf("checks: %u passed, %u failed\n", passed, failed);
    return failed == 0 ? 0 : 1;
}

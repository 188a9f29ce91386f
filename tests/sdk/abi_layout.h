/* SPDX-License-Identifier: MIT */
/* The recorded layout of the plugin ABI (64-bit targets), as one X-macro list that the C
 * and the C++ side of abi_c_test both expand: every struct size, every member offset and
 * every constant a built plugin depends on. A change here is an ABI break: bump
 * BINOCLE_ABI_VERSION (layouts) or append entries and bump BINOCLE_API_VERSION, then
 * record the new numbers.
 *
 * BINOCLE_ABI_LAYOUT(SIZE, FIELD, CONSTANT) expands SIZE(type, bytes),
 * FIELD(type, member, offset) and CONSTANT(name, value) once per entry. */
#ifndef BINOCLE_TEST_ABI_LAYOUT_H
#define BINOCLE_TEST_ABI_LAYOUT_H

#include <binocle/abi.h>

#include <stdint.h>

/* The recorded numbers hold for 64-bit pointers (LP64 and LLP64 alike). */
#define BINOCLE_ABI_LAYOUT_RECORDED (UINTPTR_MAX == 0xffffffffffffffffu)

#define BINOCLE_ABI_LAYOUT(SIZE, FIELD, CONSTANT)                                  \
    SIZE(binocle_plugin_header, 40)                                                \
    FIELD(binocle_plugin_header, struct_size, 0)                                   \
    FIELD(binocle_plugin_header, abi_version, 4)                                   \
    FIELD(binocle_plugin_header, api_version, 8)                                   \
    FIELD(binocle_plugin_header, kind, 12)                                         \
    FIELD(binocle_plugin_header, name, 16)                                         \
    FIELD(binocle_plugin_header, version, 24)                                      \
    FIELD(binocle_plugin_header, description, 32)                                  \
    SIZE(binocle_image, 24)                                                        \
    FIELD(binocle_image, width, 0)                                                 \
    FIELD(binocle_image, height, 4)                                                \
    FIELD(binocle_image, stride_bytes, 8)                                          \
    FIELD(binocle_image, format, 12)                                               \
    FIELD(binocle_image, data, 16)                                                 \
    SIZE(binocle_named_image, 32)                                                  \
    FIELD(binocle_named_image, name, 0)                                            \
    FIELD(binocle_named_image, image, 8)                                           \
    SIZE(binocle_param_desc, 72)                                                   \
    FIELD(binocle_param_desc, name, 0)                                             \
    FIELD(binocle_param_desc, type, 8)                                             \
    FIELD(binocle_param_desc, flags, 12)                                           \
    FIELD(binocle_param_desc, default_value, 16)                                   \
    FIELD(binocle_param_desc, min, 24)                                             \
    FIELD(binocle_param_desc, max, 32)                                             \
    FIELD(binocle_param_desc, multiple_of, 40)                                     \
    FIELD(binocle_param_desc, choices, 48)                                         \
    FIELD(binocle_param_desc, unit, 56)                                            \
    FIELD(binocle_param_desc, help, 64)                                            \
    SIZE(binocle_param, 48)                                                        \
    FIELD(binocle_param, name, 0)                                                  \
    FIELD(binocle_param, type, 8)                                                  \
    FIELD(binocle_param, i, 16)                                                    \
    FIELD(binocle_param, d, 24)                                                    \
    FIELD(binocle_param, s, 32)                                                    \
    FIELD(binocle_param, explicit_, 40)                                            \
    SIZE(binocle_host, 40)                                                         \
    FIELD(binocle_host, struct_size, 0)                                            \
    FIELD(binocle_host, context, 8)                                                \
    FIELD(binocle_host, log, 16)                                                   \
    FIELD(binocle_host, report_metric, 24)                                         \
    FIELD(binocle_host, report_text, 32)                                           \
    SIZE(binocle_stereo_frame, 112)                                                \
    FIELD(binocle_stereo_frame, struct_size, 0)                                    \
    FIELD(binocle_stereo_frame, frame_id, 8)                                       \
    FIELD(binocle_stereo_frame, sequence, 16)                                      \
    FIELD(binocle_stereo_frame, timestamp_left_ns, 24)                             \
    FIELD(binocle_stereo_frame, timestamp_right_ns, 32)                            \
    FIELD(binocle_stereo_frame, left, 40)                                          \
    FIELD(binocle_stereo_frame, right, 64)                                         \
    FIELD(binocle_stereo_frame, extras, 88)                                        \
    FIELD(binocle_stereo_frame, extra_count, 96)                                   \
    FIELD(binocle_stereo_frame, metadata, 104)                                     \
    SIZE(binocle_source_api, 136)                                                  \
    FIELD(binocle_source_api, header, 0)                                           \
    FIELD(binocle_source_api, params, 40)                                          \
    FIELD(binocle_source_api, param_count, 48)                                     \
    FIELD(binocle_source_api, create, 56)                                          \
    FIELD(binocle_source_api, destroy, 64)                                         \
    FIELD(binocle_source_api, last_error, 72)                                      \
    FIELD(binocle_source_api, start, 80)                                           \
    FIELD(binocle_source_api, stop, 88)                                            \
    FIELD(binocle_source_api, grab, 96)                                            \
    FIELD(binocle_source_api, release_frame, 104)                                  \
    FIELD(binocle_source_api, calibration, 112)                                    \
    FIELD(binocle_source_api, statistics, 120)                                     \
    FIELD(binocle_source_api, enumerate_devices, 128)                              \
    SIZE(binocle_matcher_api, 104)                                                 \
    FIELD(binocle_matcher_api, header, 0)                                          \
    FIELD(binocle_matcher_api, params, 40)                                         \
    FIELD(binocle_matcher_api, param_count, 48)                                    \
    FIELD(binocle_matcher_api, create, 56)                                         \
    FIELD(binocle_matcher_api, destroy, 64)                                        \
    FIELD(binocle_matcher_api, last_error, 72)                                     \
    FIELD(binocle_matcher_api, compute, 80)                                        \
    FIELD(binocle_matcher_api, disparity_range, 88)                                \
    FIELD(binocle_matcher_api, extras, 96)                                         \
    SIZE(binocle_cloud, 48)                                                        \
    FIELD(binocle_cloud, count, 0)                                                 \
    FIELD(binocle_cloud, xyz, 8)                                                   \
    FIELD(binocle_cloud, rgb, 16)                                                  \
    FIELD(binocle_cloud, pixel, 24)                                                \
    FIELD(binocle_cloud, image_width, 32)                                          \
    FIELD(binocle_cloud, image_height, 36)                                         \
    FIELD(binocle_cloud, frame, 40)                                                \
    SIZE(binocle_cloud_transform_api, 88)                                          \
    FIELD(binocle_cloud_transform_api, header, 0)                                  \
    FIELD(binocle_cloud_transform_api, params, 40)                                 \
    FIELD(binocle_cloud_transform_api, param_count, 48)                            \
    FIELD(binocle_cloud_transform_api, create, 56)                                 \
    FIELD(binocle_cloud_transform_api, destroy, 64)                                \
    FIELD(binocle_cloud_transform_api, last_error, 72)                             \
    FIELD(binocle_cloud_transform_api, apply, 80)                                  \
    SIZE(binocle_eval_input, 120)                                                  \
    FIELD(binocle_eval_input, struct_size, 0)                                      \
    FIELD(binocle_eval_input, frame, 8)                                            \
    FIELD(binocle_eval_input, rectified_left, 16)                                  \
    FIELD(binocle_eval_input, rectified_right, 24)                                 \
    FIELD(binocle_eval_input, disparity, 32)                                       \
    FIELD(binocle_eval_input, cloud, 40)                                           \
    FIELD(binocle_eval_input, calibration_yaml, 48)                                \
    FIELD(binocle_eval_input, rig_yaml, 56)                                        \
    FIELD(binocle_eval_input, output_dir, 64)                                      \
    FIELD(binocle_eval_input, min_disparity, 72)                                   \
    FIELD(binocle_eval_input, num_disparities, 76)                                 \
    FIELD(binocle_eval_input, ground_pose_known, 80)                               \
    FIELD(binocle_eval_input, camera_height_mm, 88)                                \
    FIELD(binocle_eval_input, inclination_deg, 96)                                 \
    FIELD(binocle_eval_input, disparity_extras, 104)                               \
    FIELD(binocle_eval_input, disparity_extra_count, 112)                          \
    SIZE(binocle_evaluator_api, 96)                                                \
    FIELD(binocle_evaluator_api, header, 0)                                        \
    FIELD(binocle_evaluator_api, params, 40)                                       \
    FIELD(binocle_evaluator_api, param_count, 48)                                  \
    FIELD(binocle_evaluator_api, create, 56)                                       \
    FIELD(binocle_evaluator_api, destroy, 64)                                      \
    FIELD(binocle_evaluator_api, last_error, 72)                                   \
    FIELD(binocle_evaluator_api, evaluate, 80)                                     \
    FIELD(binocle_evaluator_api, finish, 88)                                       \
    CONSTANT(BINOCLE_ABI_VERSION, 1)                                               \
    CONSTANT(BINOCLE_API_VERSION, 1)                                               \
    CONSTANT(BINOCLE_OK, 0)                                                        \
    CONSTANT(BINOCLE_ERR_INVALID_ARGUMENT, 1)                                      \
    CONSTANT(BINOCLE_ERR_NOT_FOUND, 2)                                             \
    CONSTANT(BINOCLE_ERR_IO, 3)                                                    \
    CONSTANT(BINOCLE_ERR_DEVICE, 4)                                                \
    CONSTANT(BINOCLE_ERR_TIMEOUT, 5)                                               \
    CONSTANT(BINOCLE_ERR_END_OF_STREAM, 6)                                         \
    CONSTANT(BINOCLE_ERR_UNSUPPORTED, 7)                                           \
    CONSTANT(BINOCLE_ERR_BUSY, 8)                                                  \
    CONSTANT(BINOCLE_ERR_INTERNAL, 9)                                              \
    CONSTANT(BINOCLE_ERR_VENDOR_BASE, 0x10000)                                     \
    CONSTANT(BINOCLE_KIND_STEREO_SOURCE, 1)                                        \
    CONSTANT(BINOCLE_KIND_MATCHER, 2)                                              \
    CONSTANT(BINOCLE_KIND_CLOUD_TRANSFORM, 3)                                      \
    CONSTANT(BINOCLE_KIND_EVALUATOR, 4)                                            \
    CONSTANT(BINOCLE_PIXEL_GRAY8, 1)                                               \
    CONSTANT(BINOCLE_PIXEL_GRAY16, 2)                                              \
    CONSTANT(BINOCLE_PIXEL_BGR8, 3)                                                \
    CONSTANT(BINOCLE_PIXEL_RGB8, 4)                                                \
    CONSTANT(BINOCLE_PIXEL_FLOAT32, 5)                                             \
    CONSTANT(BINOCLE_PIXEL_VENDOR_BASE, 0x10000)                                   \
    CONSTANT(BINOCLE_PARAM_BOOL, 1)                                                \
    CONSTANT(BINOCLE_PARAM_INT, 2)                                                 \
    CONSTANT(BINOCLE_PARAM_DOUBLE, 3)                                              \
    CONSTANT(BINOCLE_PARAM_STRING, 4)                                              \
    CONSTANT(BINOCLE_PARAM_ENUM, 5)                                                \
    CONSTANT(BINOCLE_PARAM_PATH, 6)                                                \
    CONSTANT(BINOCLE_PARAM_YAML, 7)                                                \
    CONSTANT(BINOCLE_PARAM_INT_LIST, 8)                                            \
    CONSTANT(BINOCLE_PARAM_DOUBLE_LIST, 9)                                         \
    CONSTANT(BINOCLE_PARAM_FLAG_REQUIRED, 1)                                       \
    CONSTANT(BINOCLE_PARAM_FLAG_ODD, 2)                                            \
    CONSTANT(BINOCLE_PARAM_FLAG_HAS_MIN, 4)                                        \
    CONSTANT(BINOCLE_PARAM_FLAG_HAS_MAX, 8)                                        \
    CONSTANT(BINOCLE_PARAM_FLAG_LIMIT, 16)                                         \
    CONSTANT(BINOCLE_LOG_DEBUG, 0)                                                 \
    CONSTANT(BINOCLE_LOG_INFO, 1)                                                  \
    CONSTANT(BINOCLE_LOG_WARNING, 2)                                               \
    CONSTANT(BINOCLE_LOG_ERROR, 3)                                                 \
    CONSTANT(BINOCLE_FRAME_CAMERA, 1)                                              \
    CONSTANT(BINOCLE_FRAME_GROUND, 2)

/* One measured entry, as the C compiler sees it (abi_layout_c11.c). */
typedef struct binocle_test_layout_entry {
    const char *what;  /* "sizeof(binocle_image)", "offsetof(binocle_image, data)", a constant's name */
    long long measured; /* by the C compiler                                                            */
    long long recorded; /* the number in this file                                                      */
} binocle_test_layout_entry;

#ifdef __cplusplus
extern "C" {
#endif

/* Implemented in C (C11): the table above as the C compiler lays it out. */
const binocle_test_layout_entry *binocle_test_c_layout(int *count);
/* Implemented in C (C99): __STDC_VERSION__ of that file, and a matcher table filled with
 * C99 designated initializers. */
long binocle_test_c99_version(void);
const binocle_plugin_header *binocle_test_c99_table(void);

#ifdef __cplusplus
}
#endif

#endif /* BINOCLE_TEST_ABI_LAYOUT_H */

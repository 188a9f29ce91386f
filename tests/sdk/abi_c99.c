/* SPDX-License-Identifier: MIT */
/* The plugin ABI compiled as C99 (-std=c99 -pedantic -Werror): every header parses, and
 * a table can be filled with designated initializers, as a C plugin author would. */
#ifdef __cplusplus
#error "abi_c99.c must be compiled as C"
#endif

#include "abi_layout.h"

#include <binocle/abi.h>

#include <stddef.h>

static binocle_result create(const binocle_param *params, int32_t count, const binocle_host *host, binocle_matcher **out) {
    (void)params;
    (void)count;
    (void)host;
    *out = NULL;
    return BINOCLE_ERR_UNSUPPORTED;
}

static void destroy(binocle_matcher *matcher) { (void)matcher; }

static const char *last_error(binocle_matcher *matcher) {
    (void)matcher;
    return "c99 table: not a real matcher";
}

static binocle_result compute(binocle_matcher *matcher, const binocle_image *left, const binocle_image *right,
                              binocle_image *disparity) {
    (void)matcher;
    (void)left;
    (void)right;
    (void)disparity;
    return BINOCLE_ERR_UNSUPPORTED;
}

static const binocle_param_desc params[] = {
    {.name = "window_px", .type = BINOCLE_PARAM_INT, .flags = BINOCLE_PARAM_FLAG_ODD | BINOCLE_PARAM_FLAG_HAS_MIN,
     .default_value = "5", .min = 1, .unit = "px", .help = "matching window"}};

static const binocle_matcher_api table = {
    .header = {.struct_size = sizeof(binocle_matcher_api),
               .abi_version = BINOCLE_ABI_VERSION,
               .api_version = BINOCLE_API_VERSION,
               .kind = BINOCLE_KIND_MATCHER,
               .name = "c99_table",
               .version = "1.0.0",
               .description = "filled in C99"},
    .params = params,
    .param_count = 1,
    .create = create,
    .destroy = destroy,
    .last_error = last_error,
    .compute = compute};

long binocle_test_c99_version(void) { return __STDC_VERSION__; }

const binocle_plugin_header *binocle_test_c99_table(void) { return &table.header; }

/* SPDX-License-Identifier: MIT */
/* Binocle plugin ABI: Matcher, rectified pair -> disparity map. */
#ifndef BINOCLE_ABI_MATCHER_H
#define BINOCLE_ABI_MATCHER_H

#include "common.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct binocle_matcher binocle_matcher; /* opaque instance */

typedef struct binocle_matcher_api {
    binocle_plugin_header header; /* kind == BINOCLE_KIND_MATCHER */

    const binocle_param_desc *params;
    int32_t param_count;

    binocle_result (*create)(const binocle_param *params, int32_t param_count,
                             const binocle_host *host, binocle_matcher **out);
    void (*destroy)(binocle_matcher *matcher);
    const char *(*last_error)(binocle_matcher *matcher);

    /* left, right: rectified, same size and format (GRAY8, BGR8 or RGB8), owned by
       the host and valid for the duration of the call only.
       disparity: FLOAT32, same size as left, allocated by the host; the matcher writes
       disparities in pixels of the left image, BINOCLE_INVALID_DISPARITY where none. */
    binocle_result (*compute)(binocle_matcher *matcher, const binocle_image *left,
                              const binocle_image *right, binocle_image *disparity);
    /* The disparity search window: min_disparity .. min_disparity + num_disparities - 1. */
    binocle_result (*disparity_range)(binocle_matcher *matcher, int32_t *min_disparity,
                                      int32_t *num_disparities);

    /* Appended after API 1, as today's matcher.h has it (see there). */
    binocle_result (*extras)(binocle_matcher *matcher, const binocle_named_image **extras,
                             int32_t *count);

    /* ---- API 2 (a test's idea of the next API: appended, never inserted) ---- */
    /* One line on how the matcher is tuned, valid until the next call. */
    binocle_result (*describe)(binocle_matcher *matcher, const char **text);
} binocle_matcher_api;

#ifdef __cplusplus
}
#endif

#endif /* BINOCLE_ABI_MATCHER_H */

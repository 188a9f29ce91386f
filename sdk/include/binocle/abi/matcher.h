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

    /* Appended after API 1: a host reads it only when header.struct_size reaches it, and a
       plugin may leave it NULL (no extras). The named planes the matcher attached to the
       disparity of its last successful compute, each of the disparity's size (GRAY8,
       GRAY16 or FLOAT32), e.g. "disparity_filled" (GRAY8, non-zero = the value was filled
       in, not matched). *extras: *count entries, names and pixels owned by the matcher,
       valid until its next compute or destroy. The host copies them and hands them to
       evaluators (binocle_eval_input.disparity_extras). */
    binocle_result (*extras)(binocle_matcher *matcher, const binocle_named_image **extras,
                             int32_t *count);
} binocle_matcher_api;

/* True when a matcher table holds `member` (an entry appended after API 1). */
#define BINOCLE_MATCHER_API_HAS(api, member)                                                   \
    ((api).header.struct_size >= offsetof(binocle_matcher_api, member) + sizeof((api).member))

#ifdef __cplusplus
}
#endif

#endif /* BINOCLE_ABI_MATCHER_H */

/* SPDX-License-Identifier: MIT */
/* Binocle plugin ABI: Evaluator, scores a frame's disparity and cloud. */
#ifndef BINOCLE_ABI_EVALUATOR_H
#define BINOCLE_ABI_EVALUATOR_H

#include "cloud_transform.h"
#include "common.h"
#include "source.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct binocle_evaluator binocle_evaluator; /* opaque instance */

/* Everything the host knows about one processed frame. Valid during the call only. */
typedef struct binocle_eval_input {
    uint32_t struct_size;
    const binocle_stereo_frame *frame; /* as the source lent it: extras, metadata   */
    const binocle_image *rectified_left;
    const binocle_image *rectified_right;
    const binocle_image *disparity;    /* FLOAT32 px, grid of rectified_left        */
    const binocle_cloud *cloud;        /* after all cloud transforms               */
    const char *calibration_yaml;      /* OpenCV FileStorage YAML text, or NULL    */
    const char *rig_yaml;              /* the resolved rig description, YAML text   */
    const char *output_dir;            /* folder the evaluator may write into, or NULL */
} binocle_eval_input;

typedef struct binocle_evaluator_api {
    binocle_plugin_header header; /* kind == BINOCLE_KIND_EVALUATOR */

    const binocle_param_desc *params;
    int32_t param_count;

    /* host->report_metric / report_text receive the evaluator's figures. */
    binocle_result (*create)(const binocle_param *params, int32_t param_count,
                             const binocle_host *host, binocle_evaluator **out);
    void (*destroy)(binocle_evaluator *evaluator);
    const char *(*last_error)(binocle_evaluator *evaluator);

    /* Scores one frame; reports its figures through the host during the call. */
    binocle_result (*evaluate)(binocle_evaluator *evaluator, const binocle_eval_input *input);
    /* After the last frame: reports figures over the whole run (may report nothing). */
    binocle_result (*finish)(binocle_evaluator *evaluator);
} binocle_evaluator_api;

#ifdef __cplusplus
}
#endif

#endif /* BINOCLE_ABI_EVALUATOR_H */

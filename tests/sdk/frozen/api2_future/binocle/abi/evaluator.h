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
    /* Appended after API 1: read these only when struct_size reaches them
       (BINOCLE_EVAL_INPUT_HAS); a host built before them passes a shorter struct.
       What the host learnt through the other plugins' tables, so that an evaluator
       reads no other plugin's settings: */
    int32_t min_disparity;     /* the matcher's search as its disparity_range answers: */
    int32_t num_disparities;   /* min .. min + num - 1; num 0 = unknown                 */
    int32_t ground_pose_known; /* 1 when the cloud's ground frame (Eq. 1) was made by a
                                  transform declaring these two settings (see
                                  cloud_transform.h); 0: the two below mean nothing    */
    double camera_height_mm;   /* hc: the left optical centre above the ground          */
    double inclination_deg;    /* theta: downward pitch of the optical axis            */
    /* The planes the matcher attached to this frame's disparity (as today's evaluator.h). */
    const binocle_named_image *disparity_extras;
    int32_t disparity_extra_count;
} binocle_eval_input;

/* True when the host's binocle_eval_input holds `member` (an entry appended after API 1). */
#define BINOCLE_EVAL_INPUT_HAS(input, member)                                                 \
    ((input).struct_size >= offsetof(binocle_eval_input, member) + sizeof((input).member))

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

/* SPDX-License-Identifier: MIT */
/* Binocle plugin ABI: CloudTransform, in-place operations on a 3D point cloud. */
#ifndef BINOCLE_ABI_CLOUD_TRANSFORM_H
#define BINOCLE_ABI_CLOUD_TRANSFORM_H

#include "common.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct binocle_cloud_transform binocle_cloud_transform; /* opaque instance */

/* Coordinate frames of METHOD.md, all in millimetres. */
enum {
    BINOCLE_FRAME_CAMERA = 1, /* origin at the left optical centre; x right, y down, z forward */
    BINOCLE_FRAME_GROUND = 2  /* origin on the ground below the left imager; X lateral (right),
                                 Y range (forward), Z height (up)                            */
};

/* A cloud owned by the host. A transform may rewrite points in place and may drop
 * points (compacting all arrays and lowering count); it never grows the cloud. */
typedef struct binocle_cloud {
    int64_t count;  /* number of points                                        */
    float *xyz;     /* 3 * count floats, millimetres, in `frame`               */
    uint8_t *rgb;   /* 3 * count bytes (R, G, B), or NULL                      */
    int32_t *pixel; /* count indices v * image_width + u of the left pixel the
                       point came from, or NULL                                */
    int32_t image_width;
    int32_t image_height;
    int32_t frame;  /* BINOCLE_FRAME_*; a transform that changes frame sets it */
} binocle_cloud;

/* A transform that puts clouds into BINOCLE_FRAME_GROUND declares the pose of Eq. 1 it
 * applies as two DOUBLE settings named camera_height_mm and inclination_deg; the host
 * hands their values to every evaluator (binocle_eval_input.ground_pose_known), so that
 * no evaluator needs to know which plugin made the frame. */
typedef struct binocle_cloud_transform_api {
    binocle_plugin_header header; /* kind == BINOCLE_KIND_CLOUD_TRANSFORM */

    const binocle_param_desc *params;
    int32_t param_count;

    binocle_result (*create)(const binocle_param *params, int32_t param_count,
                             const binocle_host *host, binocle_cloud_transform **out);
    void (*destroy)(binocle_cloud_transform *transform);
    const char *(*last_error)(binocle_cloud_transform *transform);

    binocle_result (*apply)(binocle_cloud_transform *transform, binocle_cloud *cloud);
} binocle_cloud_transform_api;

#ifdef __cplusplus
}
#endif

#endif /* BINOCLE_ABI_CLOUD_TRANSFORM_H */

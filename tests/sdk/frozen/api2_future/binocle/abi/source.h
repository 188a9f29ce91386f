/* SPDX-License-Identifier: MIT */
/* Binocle plugin ABI: StereoSource, a producer of stereo image pairs. */
#ifndef BINOCLE_ABI_SOURCE_H
#define BINOCLE_ABI_SOURCE_H

#include "common.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct binocle_source binocle_source; /* opaque instance */

/* One stereo pair, lent by the source to the host.
 *
 * Lifetime: every pointer in the frame (pixels, extras, metadata) stays valid, and
 * the pixels unchanged, until the host passes frame_id back to release_frame. The host
 * releases every frame it grabbed, before destroy. A source may lend several frames
 * at once and may refuse to lend more (BINOCLE_ERR_BUSY) until some come back.
 * No pixel is copied on the way: the source keeps ownership of its buffers. */
typedef struct binocle_stereo_frame {
    uint32_t struct_size;       /* set by the host before grab; the source fills only
                                   the members that fit                            */
    uint64_t frame_id;          /* opaque to the host; passed back to release_frame */
    uint64_t sequence;          /* 0, 1, 2 ... in acquisition order                 */
    int64_t timestamp_left_ns;  /* acquisition time of each image (any epoch)       */
    int64_t timestamp_right_ns;
    binocle_image left;         /* reference image (GRAY8, BGR8 or RGB8)            */
    binocle_image right;        /* same size and format as left                     */
    /* Extra planes, e.g. ground truth of a simulated or annotated source, in the
       pixel grid of the rectified left image:
         "gt_disparity" FLOAT32 px (<= 0 where unknown), "gt_depth" FLOAT32 mm,
         "gt_valid" GRAY8 (255 = ground truth known). */
    const binocle_named_image *extras;
    int32_t extra_count;
    /* YAML text or NULL: anything else the source knows about this frame, e.g. the
       true positions and sizes of scene objects ("objects:" list) in the ground frame. */
    const char *metadata;
} binocle_stereo_frame;

typedef struct binocle_source_api {
    binocle_plugin_header header; /* kind == BINOCLE_KIND_STEREO_SOURCE */

    const binocle_param_desc *params; /* settings accepted by create */
    int32_t param_count;

    /* Opens the source (files, devices) with validated settings. */
    binocle_result (*create)(const binocle_param *params, int32_t param_count,
                             const binocle_host *host, binocle_source **out);
    void (*destroy)(binocle_source *source);
    /* Message behind the last failure on this instance (NULL: of create). */
    const char *(*last_error)(binocle_source *source);

    binocle_result (*start)(binocle_source *source);
    binocle_result (*stop)(binocle_source *source);
    /* Waits at most timeout_ms (< 0: no limit) for the next pair.
       BINOCLE_ERR_END_OF_STREAM when a finite source is exhausted. */
    binocle_result (*grab)(binocle_source *source, int32_t timeout_ms, binocle_stereo_frame *frame);
    /* Gives a lent frame back. May be called from any thread. */
    binocle_result (*release_frame)(binocle_source *source, uint64_t frame_id);

    /* The calibration the source knows (stored on the head, shipped with a recording,
       or exact for a simulated rig) as OpenCV FileStorage YAML text in the format that
       `binocle calibrate` writes, or *yaml = NULL when it knows none. The text stays
       valid until destroy. */
    binocle_result (*calibration)(binocle_source *source, const char **yaml);
    /* Stream statistics as YAML text (frames, unpaired, missing/resent packets ...).
       Valid until the next call on the instance; may be called before start.
       Entries the host reads (all optional):
         live: true        frames come on the device's own clock (a camera), so the
                           host's default policy is `latest` (never make it wait);
         unpaired: N       (top level) images dropped for want of a partner;
         failed_buffers, underrun_buffers, corrupt, dropped_by_driver: N
                           (anywhere; in a list item with `role:` for one camera)
                           frames lost in the camera or the transport.
       The host names these in the run's summary under `dropped`. */
    binocle_result (*statistics)(binocle_source *source, const char **yaml);
    /* Lists the devices this plugin can see, as a YAML sequence of maps with at least
       "id" and "description"; needs no instance. Valid until the next call. */
    binocle_result (*enumerate_devices)(const binocle_host *host, const char **yaml);
} binocle_source_api;

#ifdef __cplusplus
}
#endif

#endif /* BINOCLE_ABI_SOURCE_H */

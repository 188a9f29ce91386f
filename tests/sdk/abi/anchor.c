/* SPDX-License-Identifier: MIT */
/* A tiny shared library whose one exported function reaches every type of the SDK, so
 * that libabigail (abidw) records their layout from its debug info; abi_check.cmake
 * compares that against the committed baseline. */
#include <binocle/abi.h>

BINOCLE_PLUGIN_EXPORT void binocle_abi_anchor(binocle_plugin_header *header, binocle_source_api *source,
                                              binocle_matcher_api *matcher, binocle_cloud_transform_api *transform,
                                              binocle_evaluator_api *evaluator, binocle_stereo_frame *frame,
                                              binocle_eval_input *input, binocle_host *host, binocle_param_desc *desc,
                                              binocle_param *param, binocle_cloud *cloud, binocle_named_image *named,
                                              binocle_image *image);

void binocle_abi_anchor(binocle_plugin_header *header, binocle_source_api *source, binocle_matcher_api *matcher,
                        binocle_cloud_transform_api *transform, binocle_evaluator_api *evaluator,
                        binocle_stereo_frame *frame, binocle_eval_input *input, binocle_host *host,
                        binocle_param_desc *desc, binocle_param *param, binocle_cloud *cloud, binocle_named_image *named,
                        binocle_image *image) {
    (void)header;
    (void)source;
    (void)matcher;
    (void)transform;
    (void)evaluator;
    (void)frame;
    (void)input;
    (void)host;
    (void)desc;
    (void)param;
    (void)cloud;
    (void)named;
    (void)image;
}

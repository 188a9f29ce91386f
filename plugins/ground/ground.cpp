// SPDX-License-Identifier: MIT
// ground: CloudTransform moving a cloud from the camera frame into the ground frame (Eq. 1).
#include "method/ground_frame.hpp"

#include <binocle/plugin.hpp>

#include <array>
#include <string>
#include <vector>

namespace {

using binocle::sdk::Param;

class GroundTransform : public binocle::sdk::CloudTransform {
public:
    static std::vector<binocle_param_desc> parameters() {
        return {
            Param::real("camera_height_mm", "1500").min(0).unit("mm")
                .help("height of the left optical centre above the ground (hc)"),
            Param::real("inclination_deg", "0").min(-90).max(90).unit("deg")
                .help("downward pitch of the optical axis (theta); 0 = horizontal"),
        };
    }

    GroundTransform(const binocle::sdk::CheckedParams &p, binocle::sdk::Host &)
        : frame_(p.real("camera_height_mm"), p.real("inclination_deg")) {}

    void apply(binocle_cloud &cloud) override {
        if (cloud.frame == BINOCLE_FRAME_GROUND)
            throw binocle::sdk::Error(BINOCLE_ERR_INVALID_ARGUMENT,
                                      "ground: the cloud is already in the ground frame: expected a camera-frame "
                                      "cloud (is `ground` listed twice in transforms?)");
        if (cloud.frame != BINOCLE_FRAME_CAMERA)
            throw binocle::sdk::Error(BINOCLE_ERR_INVALID_ARGUMENT,
                                      "ground: the cloud's frame is " + std::to_string(cloud.frame) +
                                          ": expected " + std::to_string(BINOCLE_FRAME_CAMERA) + " (camera frame)");
        if (cloud.count < 0 || (cloud.count > 0 && !cloud.xyz))
            throw binocle::sdk::Error(BINOCLE_ERR_INVALID_ARGUMENT,
                                      "ground: the cloud has count " + std::to_string(cloud.count) +
                                          " and " + (cloud.xyz ? "points" : "no points (xyz is NULL)"));
        for (int64_t i = 0; i < cloud.count; ++i) {
            float *p = cloud.xyz + 3 * i;
            const std::array<double, 3> g = frame_.toGround(p[0], p[1], p[2]);
            p[0] = static_cast<float>(g[0]);
            p[1] = static_cast<float>(g[1]);
            p[2] = static_cast<float>(g[2]);
        }
        cloud.frame = BINOCLE_FRAME_GROUND;
    }

private:
    binocle::method::GroundFrame frame_;
};

} // namespace

BINOCLE_EXPORT_CLOUD_TRANSFORM(GroundTransform, "ground", "1.0.0",
                               "Camera frame -> ground frame (METHOD.md Eq. 1), in place")

// SPDX-License-Identifier: MIT
// Conformance cases of a cloud transform: apply inside the host's arrays, an empty
// cloud, determinism.
#include "conformance/kit.hpp"

namespace binocle::conformance {

namespace {

std::vector<float> applied(const binocle_cloud_transform_api *api, binocle_cloud_transform *h, int64_t n) {
    GuardedCloud c(n);
    const binocle_cloud before = c.cloud;
    const int32_t rc = api->apply(h, &c.cloud);
    expectMessage("apply", rc, api->last_error(h));
    if (rc != BINOCLE_OK) fail("apply on a cloud of " + std::to_string(n) + " points failed (" + codeText(rc, api->last_error(h)) + ")");
    if (c.cloud.count < 0 || c.cloud.count > before.count || c.cloud.xyz != before.xyz || c.cloud.rgb != before.rgb ||
        c.cloud.pixel != before.pixel || (c.cloud.frame != BINOCLE_FRAME_CAMERA && c.cloud.frame != BINOCLE_FRAME_GROUND))
        fail("apply returned a garbage cloud (count " + std::to_string(c.cloud.count) + " of " + std::to_string(before.count) +
             ", arrays or frame changed)");
    const auto *p = c.cloud.xyz;
    return std::vector<float>(p, p + 3 * c.cloud.count);
}

} // namespace

void transformCases(Battery &b) {
    using Transform = binocle_cloud_transform;
    const Family<binocle_cloud_transform_api, Transform> f(b);
    const auto *api = f.api;
    f.createDestroyCase();
    f.instanceCase("apply_in_host_buffers", [&](Transform *h, HostBlock &) {
        const auto pts = applied(api, h, 10000);
        return pass(std::to_string(pts.size() / 3) + " of 10000 points kept; all writes inside the host's arrays");
    });
    f.instanceCase("empty_cloud", [&](Transform *h, HostBlock &) {
        binocle_cloud c{};
        c.frame = BINOCLE_FRAME_CAMERA;
        const int32_t rc = api->apply(h, &c);
        expectMessage("apply", rc, api->last_error(h));
        if (rc == BINOCLE_OK && c.count != 0) fail("apply grew an empty cloud to " + std::to_string(c.count) + " points");
        return pass(std::string("empty cloud: ") + resultName(rc));
    });
    b.run("determinism", [&] {
        HostBlock ha, hb;
        Transform *a = f.create(ha);
        Transform *c = f.create(hb);
        const auto p1 = applied(api, a, 2000), p2 = applied(api, a, 2000), p3 = applied(api, c, 2000);
        if (p1 != p2) fail("two applies of the same cloud on one instance differ");
        if (p1 != p3) fail("two instances with the same settings give different clouds");
        api->destroy(a);
        api->destroy(c);
        return pass("same cloud, same and second instance: identical points");
    });
}


} // namespace binocle::conformance

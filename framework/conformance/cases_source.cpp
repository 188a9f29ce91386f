// SPDX-License-Identifier: MIT
// Conformance cases of a stereo source: enumerate_devices, create (a missing device skips
// the rest, saying so), grab before start, lend/release accounting, release from another
// thread, BUSY, END_OF_STREAM, calibration and statistics. One function per case.
#include "conformance/kit.hpp"

#include <chrono>
#include <cstring>
#include <set>
#include <thread>

namespace binocle::conformance {

namespace {

using Clock = std::chrono::steady_clock;

struct Lent {
    binocle_stereo_frame frame{};
    uint64_t checksum = 0;
};

uint64_t checksum(const binocle_image &im) {
    const int bpp = im.format == BINOCLE_PIXEL_GRAY8 ? 1 : 3;
    uint64_t sum = 1469598103934665603ull;
    for (int32_t y = 0; y < im.height; ++y) {
        const auto *row = static_cast<const uint8_t *>(im.data) + static_cast<size_t>(y) * im.stride_bytes;
        for (int32_t x = 0; x < im.width * bpp; ++x) sum = (sum ^ row[x]) * 1099511628211ull;
    }
    return sum;
}

// grab with the frame checks of the host; returns the code.
int32_t grabChecked(const binocle_source_api *api, binocle_source *h, int32_t timeout_ms, Lent &out) {
    out.frame = binocle_stereo_frame{};
    out.frame.struct_size = sizeof(binocle_stereo_frame);
    const int32_t rc = api->grab(h, timeout_ms, &out.frame);
    expectMessage("grab", rc, api->last_error(h));
    if (rc != BINOCLE_OK) return rc;
    const auto &f = out.frame;
    for (const binocle_image *im : {&f.left, &f.right})
        if (!im->data || im->width <= 0 || im->height <= 0 ||
            (im->format != BINOCLE_PIXEL_GRAY8 && im->format != BINOCLE_PIXEL_BGR8 && im->format != BINOCLE_PIXEL_RGB8) ||
            im->stride_bytes < im->width * (im->format == BINOCLE_PIXEL_GRAY8 ? 1 : 3))
            fail("grab lent an invalid image (" + std::to_string(im->width) + "x" + std::to_string(im->height) + ", format " +
                 std::to_string(im->format) + ", stride " + std::to_string(im->stride_bytes) + ")");
    if (f.left.width != f.right.width || f.left.height != f.right.height || f.left.format != f.right.format)
        fail("grab lent left and right images of different sizes or formats");
    out.checksum = checksum(f.left);
    return rc;
}

void releaseOrFail(const binocle_source_api *api, binocle_source *h, uint64_t id) {
    const int32_t rc = api->release_frame(h, id);
    if (rc != BINOCLE_OK) fail("release_frame of lent frame id " + std::to_string(id) + " failed (" + codeText(rc, api->last_error(h)) + ")");
}

constexpr int32_t kGrabMs = 5000;

bool tolerable(int32_t rc) { return rc == BINOCLE_ERR_TIMEOUT || rc == BINOCLE_ERR_END_OF_STREAM || rc == BINOCLE_ERR_BUSY; }

Outcome enumerateDevices(const binocle_source_api *api, const ParamValues &) {
    if (!api->enumerate_devices) return skip("the table has no enumerate_devices entry");
    HostBlock host;
    const char *yaml = nullptr;
    const int32_t rc = api->enumerate_devices(&host.host, &yaml);
    expectMessage("enumerate_devices", rc, api->last_error(nullptr));
    if (rc == BINOCLE_OK && !yaml) fail("enumerate_devices returned OK without YAML text");
    return pass(rc == BINOCLE_OK ? "YAML of " + std::to_string(std::strlen(yaml)) + " bytes" : resultName(rc));
}

Outcome createCase(const binocle_source_api *api, const ParamValues &params) {
    HostBlock host;
    binocle_source *h = nullptr;
    const int32_t rc = api->create(params.data(), params.size(), &host.host, &h);
    expectMessage("create", rc, api->last_error(nullptr));
    if (rc == BINOCLE_ERR_NOT_FOUND || rc == BINOCLE_ERR_DEVICE || rc == BINOCLE_ERR_TIMEOUT || rc == BINOCLE_ERR_IO)
        return skip("needs a device or its files: create failed (" + codeText(rc, api->last_error(nullptr)) + ")");
    if (rc != BINOCLE_OK || !h) fail("create failed (" + codeText(rc ? rc : BINOCLE_ERR_INTERNAL, api->last_error(nullptr)) + ")");
    api->destroy(h);
    return pass();
}

Outcome grabBeforeStart(const binocle_source_api *api, const ParamValues &params) {
    HostBlock host;
    binocle_source *h = createOrFail<binocle_source_api, binocle_source>(api, params, host);
    Lent f;
    const int32_t rc = grabChecked(api, h, 1000, f);
    if (rc == BINOCLE_OK) releaseOrFail(api, h, f.frame.frame_id);
    api->destroy(h);
    return pass(std::string("grab before start: ") + resultName(rc));
}

Outcome lendReleaseAccounting(const binocle_source_api *api, const ParamValues &params) {
    HostBlock host;
    binocle_source *h = createOrFail<binocle_source_api, binocle_source>(api, params, host);
    if (api->start && api->start(h) != BINOCLE_OK) fail("start failed (" + codeText(BINOCLE_ERR_INTERNAL, api->last_error(h)) + ")");
    std::vector<Lent> lent;
    int32_t last = BINOCLE_OK;
    while (lent.size() < 4) {
        Lent f;
        last = grabChecked(api, h, kGrabMs, f);
        if (last != BINOCLE_OK) break;
        lent.push_back(f);
    }
    if (lent.empty()) {
        if (tolerable(last)) return skip(std::string("no frame to check: grab gave ") + resultName(last));
        fail(std::string("grab failed: ") + codeText(last, api->last_error(h)));
    }
    std::set<uint64_t> ids;
    for (const auto &f : lent) ids.insert(f.frame.frame_id);
    if (ids.size() != lent.size()) fail("frames lent at once share a frame_id");
    // Lent pixels stay unchanged until released, whatever was grabbed since.
    for (const auto &f : lent)
        if (checksum(f.frame.left) != f.checksum) fail("the pixels of lent frame id " + std::to_string(f.frame.frame_id) + " changed before it was released");
    for (const auto &f : lent) releaseOrFail(api, h, f.frame.frame_id);
    const uint64_t again = lent.front().frame.frame_id;
    int32_t rc = api->release_frame(h, again);
    if (rc == BINOCLE_OK) fail("a second release_frame of frame id " + std::to_string(again) + " returned OK");
    expectMessage("release_frame", rc, api->last_error(h));
    rc = api->release_frame(h, 0xdeadbeefull);
    if (rc == BINOCLE_OK) fail("release_frame of an id never lent returned OK");
    expectMessage("release_frame", rc, api->last_error(h));
    if (api->stop) api->stop(h);
    api->destroy(h);
    return pass(std::to_string(lent.size()) + " frames lent at once, distinct ids, pixels stable, double and unknown releases refused");
}

Outcome releaseFromAnotherThread(const binocle_source_api *api, const ParamValues &params) {
    HostBlock host;
    binocle_source *h = createOrFail<binocle_source_api, binocle_source>(api, params, host);
    if (api->start) api->start(h);
    Lent f;
    const int32_t rc = grabChecked(api, h, kGrabMs, f);
    if (rc != BINOCLE_OK) {
        if (tolerable(rc)) return skip(std::string("no frame: grab gave ") + resultName(rc));
        fail("grab failed (" + codeText(rc, api->last_error(h)) + ")");
    }
    int32_t released = -1;
    std::thread([&] { released = api->release_frame(h, f.frame.frame_id); }).join();
    if (released != BINOCLE_OK) fail("release_frame from another thread failed (" + codeText(released, api->last_error(h)) + ")");
    Lent next;
    const int32_t rc2 = grabChecked(api, h, kGrabMs, next);
    if (rc2 == BINOCLE_OK) releaseOrFail(api, h, next.frame.frame_id);
    if (api->stop) api->stop(h);
    api->destroy(h);
    return pass("released from a second thread; the next grab gave " + std::string(resultName(rc2)));
}

Outcome busy(const binocle_source_api *api, const ParamValues &params) {
    HostBlock host;
    binocle_source *h = createOrFail<binocle_source_api, binocle_source>(api, params, host);
    if (api->start) api->start(h);
    std::vector<Lent> lent;
    int32_t rc = BINOCLE_OK;
    constexpr size_t kMost = 32;
    while (lent.size() < kMost) {
        Lent f;
        rc = grabChecked(api, h, kGrabMs, f);
        if (rc != BINOCLE_OK) break;
        lent.push_back(f);
    }
    std::string seen;
    if (rc == BINOCLE_ERR_BUSY) {
        releaseOrFail(api, h, lent.front().frame.frame_id);
        lent.erase(lent.begin());
        Lent f;
        const int32_t after = grabChecked(api, h, kGrabMs, f);
        if (after == BINOCLE_ERR_BUSY) fail("still BUSY after a frame was released");
        if (after == BINOCLE_OK) lent.push_back(f);
        seen = "BUSY after " + std::to_string(lent.size()) + " lent frames; a release makes room";
    } else if (rc == BINOCLE_OK) {
        seen = "lends at least " + std::to_string(kMost) + " frames at once without BUSY";
    } else if (tolerable(rc)) {
        seen = std::to_string(lent.size()) + " frames lent, then " + resultName(rc);
    } else {
        fail("grab failed with " + std::to_string(lent.size()) + " frames lent (" + codeText(rc, api->last_error(h)) + ")");
    }
    for (const auto &f : lent) releaseOrFail(api, h, f.frame.frame_id);
    if (api->stop) api->stop(h);
    api->destroy(h);
    return pass(seen);
}

Outcome endOfStream(const binocle_source_api *api, const ParamValues &params) {
    HostBlock host;
    binocle_source *h = createOrFail<binocle_source_api, binocle_source>(api, params, host);
    if (api->start) api->start(h);
    constexpr int kMost = 1000;
    const auto until = Clock::now() + std::chrono::seconds(8);
    int n = 0;
    int32_t rc = BINOCLE_OK;
    for (; n < kMost && Clock::now() < until; ++n) {
        Lent f;
        rc = grabChecked(api, h, kGrabMs, f);
        if (rc != BINOCLE_OK) break;
        releaseOrFail(api, h, f.frame.frame_id);
    }
    if (rc == BINOCLE_OK) {
        api->destroy(h);
        return skip("no END_OF_STREAM within " + std::to_string(n) + " frames (a live or long source)");
    }
    if (rc != BINOCLE_ERR_END_OF_STREAM) fail("grab #" + std::to_string(n) + " failed (" + codeText(rc, api->last_error(h)) + ")");
    Lent f;
    const int32_t again = grabChecked(api, h, 100, f);
    if (again != BINOCLE_ERR_END_OF_STREAM) fail(std::string("after END_OF_STREAM the next grab gave ") + resultName(again));
    if (api->stop) api->stop(h);
    api->destroy(h);
    return pass("END_OF_STREAM after " + std::to_string(n) + " frames, and again on the next grab");
}

Outcome calibrationAndStatistics(const binocle_source_api *api, const ParamValues &params) {
    HostBlock host;
    binocle_source *h = createOrFail<binocle_source_api, binocle_source>(api, params, host);
    std::string seen;
    if (api->calibration) {
        const char *yaml = nullptr;
        const int32_t rc = api->calibration(h, &yaml);
        expectMessage("calibration", rc, api->last_error(h));
        seen += std::string("calibration: ") + (rc != BINOCLE_OK ? resultName(rc) : yaml ? "YAML" : "none") + "; ";
    }
    if (api->statistics) {
        const char *yaml = nullptr;
        const int32_t rc = api->statistics(h, &yaml);
        expectMessage("statistics", rc, api->last_error(h));
        seen += std::string("statistics: ") + (rc != BINOCLE_OK ? resultName(rc) : yaml ? "YAML" : "none");
    }
    api->destroy(h);
    return pass(seen);
}

} // namespace

void sourceCases(Battery &b) {
    const Family<binocle_source_api, binocle_source> f(b);
    const auto *api = f.api;
    const ParamValues &params = b.params;
    b.cases.push_back(runCase("enumerate_devices", b.timeout_ms, [&] { return enumerateDevices(api, params); }));
    // Without a device, create fails: the cases that need an instance are skipped, saying so.
    const ConformanceCase probe = runCase("create", b.timeout_ms, [&] { return createCase(api, params); });
    b.cases.push_back(probe);
    if (probe.status != Status::Passed) {
        b.skipAll = probe.status == Status::Skipped ? probe.message : "create failed";
    }
    f.createDestroyCase();
    b.run("grab_before_start", [&] { return grabBeforeStart(api, params); });
    b.run("lend_release_accounting", [&] { return lendReleaseAccounting(api, params); });
    b.run("release_from_another_thread", [&] { return releaseFromAnotherThread(api, params); });
    b.run("busy", [&] { return busy(api, params); });
    b.run("end_of_stream", [&] { return endOfStream(api, params); });
    b.run("calibration_and_statistics", [&] { return calibrationAndStatistics(api, params); });
}


} // namespace binocle::conformance

// SPDX-License-Identifier: MIT
// Conformance cases of a matcher: compute in guarded host buffers, colour formats,
// determinism, errors as codes, disparity_range.
#include "conformance/kit.hpp"

#include <cmath>
#include <cstring>

namespace binocle::conformance {

namespace {

// ---- Matcher -------------------------------------------------------------------------------------

// Runs compute on guarded buffers (inputs read-only); returns the disparity.
cv::Mat guardedCompute(const binocle_matcher_api *api, binocle_matcher *h, const cv::Mat &left, const cv::Mat &right,
                       int32_t format) {
    const int bpp = static_cast<int>(left.elemSize());
    const size_t bytes = static_cast<size_t>(left.cols) * left.rows * bpp;
    Guarded l(bytes), r(bytes), d(static_cast<size_t>(left.cols) * left.rows * sizeof(float));
    std::memcpy(l.data(), left.data, bytes);
    std::memcpy(r.data(), right.data, bytes);
    l.readOnly();
    r.readOnly();
    std::fill_n(reinterpret_cast<float *>(d.data()), left.cols * left.rows, BINOCLE_INVALID_DISPARITY);
    binocle_image li = imageOf(l.data(), left.cols, left.rows, format, bpp);
    binocle_image ri = imageOf(r.data(), left.cols, left.rows, format, bpp);
    binocle_image di = imageOf(d.data(), left.cols, left.rows, BINOCLE_PIXEL_FLOAT32, 4);
    const binocle_image expected = di;
    const int32_t rc = api->compute(h, &li, &ri, &di);
    expectMessage("compute", rc, api->last_error(h));
    if (rc != BINOCLE_OK) fail("compute on a textured " + std::to_string(left.cols) + "x" + std::to_string(left.rows) + " pair failed (" + codeText(rc, api->last_error(h)) + ")");
    if (std::memcmp(&di, &expected, sizeof di) != 0) fail("compute changed the host's disparity image description instead of writing into it");
    return cv::Mat(left.rows, left.cols, CV_32F, d.data()).clone();
}

} // namespace

void matcherCases(Battery &b) {
    const Family<binocle_matcher_api, binocle_matcher> f(b);
    const auto *api = f.api;
    f.createDestroyCase();
    f.instanceCase("compute_in_host_buffers", [&](binocle_matcher *h, HostBlock &) {
        // Guard pages around every buffer; inputs read-only: a write to them, or past any
        // end, kills this case with SIGSEGV.
        cv::Mat left, right;
        texturedPair(left, right, 320, 240, CV_8UC1);
        cv::Mat d = guardedCompute(api, h, left, right, BINOCLE_PIXEL_GRAY8);
        int nonFinite = 0, valid = 0;
        for (int y = 0; y < d.rows; ++y)
            for (int x = 0; x < d.cols; ++x) {
                const float v = d.at<float>(y, x);
                if (!std::isfinite(v)) ++nonFinite;
                else if (v > 0) ++valid;
            }
        if (nonFinite) fail(std::to_string(nonFinite) + " disparities are not finite (write BINOCLE_INVALID_DISPARITY instead)");
        return pass("GRAY8 320x240: " + std::to_string(valid) + " valid disparities, all writes inside the host's buffer");
    });
    f.instanceCase("colour_formats", [&](binocle_matcher *h, HostBlock &) {
        std::string seen;
        for (int32_t format : {BINOCLE_PIXEL_BGR8, BINOCLE_PIXEL_RGB8}) {
            cv::Mat left, right;
            texturedPair(left, right, 160, 120, CV_8UC3);
            const size_t bytes = left.total() * 3;
            Guarded l(bytes), r(bytes), d(left.total() * sizeof(float));
            std::memcpy(l.data(), left.data, bytes);
            std::memcpy(r.data(), right.data, bytes);
            l.readOnly();
            r.readOnly();
            binocle_image li = imageOf(l.data(), 160, 120, format, 3), ri = imageOf(r.data(), 160, 120, format, 3);
            binocle_image di = imageOf(d.data(), 160, 120, BINOCLE_PIXEL_FLOAT32, 4);
            const int32_t rc = api->compute(h, &li, &ri, &di);
            expectMessage("compute", rc, api->last_error(h));
            seen += std::string(format == BINOCLE_PIXEL_BGR8 ? "BGR8 " : "RGB8 ") + (rc == BINOCLE_OK ? "ok" : resultName(rc)) + "; ";
        }
        return pass(seen);
    });
    b.run("determinism", [&] {
        HostBlock ha, hb;
        binocle_matcher *a = f.create(ha);
        binocle_matcher *c = f.create(hb);
        cv::Mat left, right;
        texturedPair(left, right, 160, 120, CV_8UC1);
        const cv::Mat d1 = guardedCompute(api, a, left, right, BINOCLE_PIXEL_GRAY8);
        const cv::Mat d2 = guardedCompute(api, a, left, right, BINOCLE_PIXEL_GRAY8);
        const cv::Mat d3 = guardedCompute(api, c, left, right, BINOCLE_PIXEL_GRAY8);
        if (std::memcmp(d1.data, d2.data, d1.total() * 4) != 0) fail("two computes of the same pair on one instance differ");
        if (std::memcmp(d1.data, d3.data, d1.total() * 4) != 0) fail("two instances with the same settings give different disparities");
        api->destroy(a);
        api->destroy(c);
        return pass("same pair, same instance and a second instance: identical disparities");
    });
    f.instanceCase("errors_as_codes", [&](binocle_matcher *h, HostBlock &) {
        // Calls the host never makes: any answer will do but a crash, an exception or a
        // failure without a message.
        std::string seen;
        for (int32_t format : {static_cast<int32_t>(BINOCLE_PIXEL_FLOAT32), static_cast<int32_t>(0x7777)}) {
            std::vector<float> l(64 * 48, 1.0f), r(64 * 48, 1.0f), d(64 * 48, 0.0f);
            binocle_image li = imageOf(l.data(), 64, 48, format, 4), ri = imageOf(r.data(), 64, 48, format, 4);
            binocle_image di = imageOf(d.data(), 64, 48, BINOCLE_PIXEL_FLOAT32, 4);
            const int32_t rc = api->compute(h, &li, &ri, &di);
            expectMessage("compute", rc, api->last_error(h));
            seen += "input format " + std::to_string(format) + ": " + resultName(rc) + "; ";
        }
        std::vector<uint8_t> one(1, 0);
        std::vector<float> d1(1, 0.0f);
        binocle_image li = imageOf(one.data(), 1, 1, BINOCLE_PIXEL_GRAY8, 1), di = imageOf(d1.data(), 1, 1, BINOCLE_PIXEL_FLOAT32, 4);
        const int32_t rc = api->compute(h, &li, &li, &di);
        expectMessage("compute", rc, api->last_error(h));
        seen += std::string("1x1 pair: ") + resultName(rc);
        return pass(seen);
    });
    b.run("disparity_range", [&] {
        if (!api->disparity_range) return skip("the table has no disparity_range entry");
        HostBlock host;
        binocle_matcher *h = f.create(host);
        int32_t mn = -12345, num = -12345;
        const int32_t rc = api->disparity_range(h, &mn, &num);
        expectMessage("disparity_range", rc, api->last_error(h));
        if (rc == BINOCLE_OK && num < 0) fail("disparity_range gives a negative number of disparities (" + std::to_string(num) + ")");
        api->destroy(h);
        return pass(rc == BINOCLE_OK ? "min " + std::to_string(mn) + ", num " + std::to_string(num) : resultName(rc));
    });
}


} // namespace binocle::conformance

// SPDX-License-Identifier: MIT
// The conformance kit: per kind, a battery of cases run against the raw C table, each in
// a child process of its own.
#include "conformance/conformance.hpp"

#include "config/rig_config.hpp"
#include "core/error.hpp"
#include "host/isolation.hpp"
#include "host/plugin_host.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <functional>
#include <map>
#include <opencv2/core.hpp>
#include <poll.h>
#include <set>
#include <sstream>
#include <spdlog/spdlog.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

namespace fs = std::filesystem;

namespace binocle {

int ConformanceReport::count(ConformanceCase::Status s) const {
    return static_cast<int>(std::count_if(cases.begin(), cases.end(), [&](const ConformanceCase &c) { return c.status == s; }));
}

namespace {

using Status = ConformanceCase::Status;
using Clock = std::chrono::steady_clock;

struct Outcome {
    Status status = Status::Passed;
    std::string message;
};

Outcome pass(std::string m = "") { return {Status::Passed, std::move(m)}; }
Outcome failure(std::string m) { return {Status::Failed, std::move(m)}; }
Outcome skip(std::string m) { return {Status::Skipped, std::move(m)}; }

// A failed expectation inside a case: ends it as failed with the message.
struct CaseFailure {
    std::string message;
};
[[noreturn]] void fail(const std::string &m) { throw CaseFailure{m}; }

// Runs `body` in a child process; a crash or a timeout is a failure naming the signal.
ConformanceCase runCase(const std::string &name, int32_t timeout_ms, const std::function<Outcome()> &body) {
    ConformanceCase c;
    c.name = name;
    const auto t0 = Clock::now();
    int fds[2];
    if (::pipe2(fds, O_CLOEXEC) != 0) {
        c.status = Status::Failed;
        c.message = "cannot run the case: pipe failed";
        return c;
    }
    std::fflush(nullptr);
    const pid_t pid = ::fork();
    if (pid == 0) {
        ::close(fds[0]);
        Outcome o;
        try {
            o = body();
        } catch (const CaseFailure &f) {
            o = failure(f.message);
        } catch (const std::exception &e) {
            o = failure(e.what());
        }
        const std::string out = std::string(1, "PFS"[static_cast<int>(o.status)]) + o.message;
        const char *p = out.data();
        size_t left = out.size();
        while (left > 0) {
            const ssize_t n = ::write(fds[1], p, left);
            if (n <= 0) break;
            p += n;
            left -= static_cast<size_t>(n);
        }
        ::_exit(0);
    }
    ::close(fds[1]);
    std::string out;
    bool timedOut = false;
    const auto deadline = t0 + std::chrono::milliseconds(timeout_ms);
    for (;;) {
        const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
        if (left <= 0) {
            timedOut = true;
            break;
        }
        pollfd p{fds[0], POLLIN, 0};
        if (::poll(&p, 1, static_cast<int>(left)) <= 0) continue;
        char buf[4096];
        const ssize_t n = ::read(fds[0], buf, sizeof buf);
        if (n <= 0) break;
        out.append(buf, static_cast<size_t>(n));
    }
    ::close(fds[0]);
    if (timedOut) ::kill(pid, SIGKILL);
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    c.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    if (timedOut) {
        c.status = Status::Failed;
        c.message = "did not finish within " + std::to_string(timeout_ms) + " ms (a call hangs?); killed";
    } else if (WIFSIGNALED(status) || out.empty()) {
        c.status = Status::Failed;
        c.message = "crashed: " + describeExit(status);
        if (WIFSIGNALED(status) && WTERMSIG(status) == SIGABRT)
            c.message += " (an exception that crossed the ABI, or an assertion, ends this way)";
    } else {
        c.status = out[0] == 'P' ? Status::Passed : out[0] == 'S' ? Status::Skipped : Status::Failed;
        c.message = out.substr(1);
    }
    return c;
}

// ---- Host services for the instances under test ---------------------------------------------

struct Recorder {
    std::vector<std::pair<std::string, double>> metrics;
    std::vector<std::pair<std::string, std::string>> texts;
};

void recLog(void *, int32_t level, const char *message) {
    if (level >= BINOCLE_LOG_WARNING) spdlog::debug("plugin says: {}", message ? message : "");
}
void recMetric(void *ctx, const char *name, double value, const char *) {
    static_cast<Recorder *>(ctx)->metrics.emplace_back(name ? name : "", value);
}
void recText(void *ctx, const char *name, const char *text) {
    static_cast<Recorder *>(ctx)->texts.emplace_back(name ? name : "", text ? text : "");
}

struct HostBlock {
    Recorder recorder;
    binocle_host host{};
    HostBlock() {
        host.struct_size = sizeof(binocle_host);
        host.context = &recorder;
        host.log = &recLog;
        host.report_metric = &recMetric;
        host.report_text = &recText;
    }
};

std::string codeText(int32_t rc, const char *message) {
    std::string s = resultName(rc);
    if (message && *message) s += ": " + std::string(message);
    return s;
}

// A failed call must say why: a non-OK code with an empty last_error is a defect.
void expectMessage(const char *call, int32_t rc, const char *message) {
    if (rc != BINOCLE_OK && (!message || !*message))
        fail(std::string(call) + " returned " + resultName(rc) + " but last_error gives no message");
}

// ---- Memory with guard pages -----------------------------------------------------------------

// `bytes` of memory whose end abuts an inaccessible page, with another one before the
// first page: a write or read past either end is a SIGSEGV in the case's child.
class Guarded {
public:
    explicit Guarded(size_t bytes) : bytes_(std::max<size_t>(bytes, 1)) {
        page_ = static_cast<size_t>(::sysconf(_SC_PAGESIZE));
        span_ = (bytes_ + page_ - 1) / page_ * page_;
        void *p = ::mmap(nullptr, span_ + 2 * page_, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
        if (p == MAP_FAILED) throw Error("cannot map guarded memory");
        base_ = static_cast<uint8_t *>(p);
        ::mprotect(base_, page_, PROT_NONE);
        ::mprotect(base_ + page_ + span_, page_, PROT_NONE);
        data_ = base_ + page_ + (span_ - bytes_);
    }
    ~Guarded() { ::munmap(base_, span_ + 2 * page_); }
    Guarded(const Guarded &) = delete;
    Guarded &operator=(const Guarded &) = delete;
    uint8_t *data() { return data_; }
    // Inputs are the host's: a plugin may read them, never write.
    void readOnly() { ::mprotect(base_ + page_, span_, PROT_READ); }

private:
    size_t bytes_, page_ = 4096, span_ = 0;
    uint8_t *base_ = nullptr, *data_ = nullptr;
};

// A textured pair: right is left shifted by 8 px, so a matcher finds disparity 8.
void texturedPair(cv::Mat &left, cv::Mat &right, int width, int height, int type) {
    cv::RNG rng(1234);
    left.create(height, width, type);
    rng.fill(left, cv::RNG::UNIFORM, 0, 256);
    right = cv::Mat::zeros(left.size(), type);
    left.colRange(8, width).copyTo(right.colRange(0, width - 8));
}

binocle_image imageOf(void *data, int width, int height, int32_t format, int bpp) {
    binocle_image im{};
    im.width = width;
    im.height = height;
    im.stride_bytes = width * bpp;
    im.format = format;
    im.data = data;
    return im;
}

// ---- Instances -----------------------------------------------------------------------------------

struct Battery {
    const PluginRecord &record;
    const ParamValues &params;
    int32_t timeout_ms;
    std::vector<ConformanceCase> &cases;
    std::string skipAll; // set when instances cannot be made (a device is missing ...)

    void run(const std::string &name, const std::function<Outcome()> &body) {
        if (!skipAll.empty()) {
            cases.push_back({name, Status::Skipped, skipAll, 0});
            return;
        }
        cases.push_back(runCase(name, timeout_ms, body));
    }
};

template <class Api, class Handle>
Handle *createOrFail(const Api *api, const ParamValues &params, HostBlock &host) {
    Handle *h = nullptr;
    const int32_t rc = api->create(params.data(), params.size(), &host.host, &h);
    if (rc != BINOCLE_OK || !h) fail("create failed (" + codeText(rc ? rc : BINOCLE_ERR_INTERNAL, api->last_error(nullptr)) + ")");
    return h;
}

template <class Api, class Handle>
Outcome createDestroyCycles(const Api *api, const ParamValues &params) {
    constexpr int kCycles = 10;
    for (int i = 0; i < kCycles; ++i) {
        HostBlock host;
        Handle *h = createOrFail<Api, Handle>(api, params, host);
        api->destroy(h);
    }
    // Two instances at once are independent.
    HostBlock a, b;
    Handle *ha = createOrFail<Api, Handle>(api, params, a);
    Handle *hb = createOrFail<Api, Handle>(api, params, b);
    if (ha == hb) fail("two creates returned the same handle");
    api->destroy(ha);
    api->destroy(hb);
    return pass(std::to_string(kCycles) + " create/destroy cycles, then two instances at once");
}

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

void matcherCases(Battery &b) {
    auto api = reinterpret_cast<const binocle_matcher_api *>(b.record.table);
    const ParamValues &params = b.params;
    b.run("create_destroy", [&] { return createDestroyCycles<binocle_matcher_api, binocle_matcher>(api, params); });
    b.run("compute_in_host_buffers", [&] {
        // Guard pages around every buffer; inputs read-only: a write to them, or past any
        // end, kills this case with SIGSEGV.
        HostBlock host;
        binocle_matcher *h = createOrFail<binocle_matcher_api, binocle_matcher>(api, params, host);
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
        api->destroy(h);
        return pass("GRAY8 320x240: " + std::to_string(valid) + " valid disparities, all writes inside the host's buffer");
    });
    b.run("colour_formats", [&] {
        HostBlock host;
        binocle_matcher *h = createOrFail<binocle_matcher_api, binocle_matcher>(api, params, host);
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
        api->destroy(h);
        return pass(seen);
    });
    b.run("determinism", [&] {
        HostBlock ha, hb;
        binocle_matcher *a = createOrFail<binocle_matcher_api, binocle_matcher>(api, params, ha);
        binocle_matcher *c = createOrFail<binocle_matcher_api, binocle_matcher>(api, params, hb);
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
    b.run("errors_as_codes", [&] {
        // Calls the host never makes: any answer will do but a crash, an exception or a
        // failure without a message.
        HostBlock host;
        binocle_matcher *h = createOrFail<binocle_matcher_api, binocle_matcher>(api, params, host);
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
        api->destroy(h);
        return pass(seen);
    });
    b.run("disparity_range", [&] {
        if (!api->disparity_range) return skip("the table has no disparity_range entry");
        HostBlock host;
        binocle_matcher *h = createOrFail<binocle_matcher_api, binocle_matcher>(api, params, host);
        int32_t mn = -12345, num = -12345;
        const int32_t rc = api->disparity_range(h, &mn, &num);
        expectMessage("disparity_range", rc, api->last_error(h));
        if (rc == BINOCLE_OK && num < 0) fail("disparity_range gives a negative number of disparities (" + std::to_string(num) + ")");
        api->destroy(h);
        return pass(rc == BINOCLE_OK ? "min " + std::to_string(mn) + ", num " + std::to_string(num) : resultName(rc));
    });
}

// ---- Source --------------------------------------------------------------------------------------

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

bool tolerable(int32_t rc) { return rc == BINOCLE_ERR_TIMEOUT || rc == BINOCLE_ERR_END_OF_STREAM || rc == BINOCLE_ERR_BUSY; }

void sourceCases(Battery &b) {
    auto api = reinterpret_cast<const binocle_source_api *>(b.record.table);
    const ParamValues &params = b.params;
    constexpr int32_t kGrabMs = 5000;
    b.cases.push_back(runCase("enumerate_devices", b.timeout_ms, [&] {
        if (!api->enumerate_devices) return skip("the table has no enumerate_devices entry");
        HostBlock host;
        const char *yaml = nullptr;
        const int32_t rc = api->enumerate_devices(&host.host, &yaml);
        expectMessage("enumerate_devices", rc, api->last_error(nullptr));
        if (rc == BINOCLE_OK && !yaml) fail("enumerate_devices returned OK without YAML text");
        return pass(rc == BINOCLE_OK ? "YAML of " + std::to_string(std::strlen(yaml)) + " bytes" : resultName(rc));
    }));
    // Without a device, create fails: the cases that need an instance are skipped, saying so.
    const ConformanceCase probe = runCase("create", b.timeout_ms, [&] {
        HostBlock host;
        binocle_source *h = nullptr;
        const int32_t rc = api->create(params.data(), params.size(), &host.host, &h);
        expectMessage("create", rc, api->last_error(nullptr));
        if (rc == BINOCLE_ERR_NOT_FOUND || rc == BINOCLE_ERR_DEVICE || rc == BINOCLE_ERR_TIMEOUT || rc == BINOCLE_ERR_IO)
            return skip("needs a device or its files: create failed (" + codeText(rc, api->last_error(nullptr)) + ")");
        if (rc != BINOCLE_OK || !h) fail("create failed (" + codeText(rc ? rc : BINOCLE_ERR_INTERNAL, api->last_error(nullptr)) + ")");
        api->destroy(h);
        return pass();
    });
    b.cases.push_back(probe);
    if (probe.status != Status::Passed) {
        b.skipAll = probe.status == Status::Skipped ? probe.message : "create failed";
    }
    b.run("create_destroy", [&] { return createDestroyCycles<binocle_source_api, binocle_source>(api, params); });
    b.run("grab_before_start", [&] {
        HostBlock host;
        binocle_source *h = createOrFail<binocle_source_api, binocle_source>(api, params, host);
        Lent f;
        const int32_t rc = grabChecked(api, h, 1000, f);
        if (rc == BINOCLE_OK) releaseOrFail(api, h, f.frame.frame_id);
        api->destroy(h);
        return pass(std::string("grab before start: ") + resultName(rc));
    });
    b.run("lend_release_accounting", [&] {
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
    });
    b.run("release_from_another_thread", [&] {
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
    });
    b.run("busy", [&] {
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
    });
    b.run("end_of_stream", [&] {
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
    });
    b.run("calibration_and_statistics", [&] {
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
    });
}

// ---- CloudTransform ------------------------------------------------------------------------------

// A cloud of n points in front of the camera, in guarded memory.
struct GuardedCloud {
    explicit GuardedCloud(int64_t n)
        : xyz(static_cast<size_t>(n) * 3 * sizeof(float)), rgb(static_cast<size_t>(n) * 3),
          pixel(static_cast<size_t>(n) * sizeof(int32_t)) {
        cv::RNG rng(99);
        auto *p = reinterpret_cast<float *>(xyz.data());
        for (int64_t i = 0; i < n; ++i) {
            p[3 * i] = static_cast<float>(rng.uniform(-2000.0, 2000.0));
            p[3 * i + 1] = static_cast<float>(rng.uniform(-500.0, 1500.0));
            p[3 * i + 2] = static_cast<float>(rng.uniform(1000.0, 20000.0));
            rgb.data()[3 * i] = rgb.data()[3 * i + 1] = rgb.data()[3 * i + 2] = static_cast<uint8_t>(i);
            reinterpret_cast<int32_t *>(pixel.data())[i] = static_cast<int32_t>(i);
        }
        cloud.count = n;
        cloud.xyz = p;
        cloud.rgb = rgb.data();
        cloud.pixel = reinterpret_cast<int32_t *>(pixel.data());
        cloud.image_width = 100;
        cloud.image_height = static_cast<int32_t>((n + 99) / 100);
        cloud.frame = BINOCLE_FRAME_CAMERA;
    }
    Guarded xyz, rgb, pixel;
    binocle_cloud cloud{};
};

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

void transformCases(Battery &b) {
    auto api = reinterpret_cast<const binocle_cloud_transform_api *>(b.record.table);
    const ParamValues &params = b.params;
    b.run("create_destroy", [&] { return createDestroyCycles<binocle_cloud_transform_api, binocle_cloud_transform>(api, params); });
    b.run("apply_in_host_buffers", [&] {
        HostBlock host;
        auto *h = createOrFail<binocle_cloud_transform_api, binocle_cloud_transform>(api, params, host);
        const auto pts = applied(api, h, 10000);
        api->destroy(h);
        return pass(std::to_string(pts.size() / 3) + " of 10000 points kept; all writes inside the host's arrays");
    });
    b.run("empty_cloud", [&] {
        HostBlock host;
        auto *h = createOrFail<binocle_cloud_transform_api, binocle_cloud_transform>(api, params, host);
        binocle_cloud c{};
        c.frame = BINOCLE_FRAME_CAMERA;
        const int32_t rc = api->apply(h, &c);
        expectMessage("apply", rc, api->last_error(h));
        if (rc == BINOCLE_OK && c.count != 0) fail("apply grew an empty cloud to " + std::to_string(c.count) + " points");
        api->destroy(h);
        return pass(std::string("empty cloud: ") + resultName(rc));
    });
    b.run("determinism", [&] {
        HostBlock ha, hb;
        auto *a = createOrFail<binocle_cloud_transform_api, binocle_cloud_transform>(api, params, ha);
        auto *c = createOrFail<binocle_cloud_transform_api, binocle_cloud_transform>(api, params, hb);
        const auto p1 = applied(api, a, 2000), p2 = applied(api, a, 2000), p3 = applied(api, c, 2000);
        if (p1 != p2) fail("two applies of the same cloud on one instance differ");
        if (p1 != p3) fail("two instances with the same settings give different clouds");
        api->destroy(a);
        api->destroy(c);
        return pass("same cloud, same and second instance: identical points");
    });
}

// ---- Evaluator -----------------------------------------------------------------------------------

// Scores one synthetic frame (constant disparity 8 on a textured pair, with ground truth)
// on read-only guarded inputs; returns the figures it reported.
std::vector<std::pair<std::string, double>> evaluated(const binocle_evaluator_api *api, binocle_evaluator *h, HostBlock &host) {
    constexpr int w = 160, hgt = 120;
    cv::Mat left, right;
    texturedPair(left, right, w, hgt, CV_8UC1);
    Guarded l(left.total()), r(right.total()), d(left.total() * 4), gt(left.total() * 4);
    std::memcpy(l.data(), left.data, left.total());
    std::memcpy(r.data(), right.data, right.total());
    std::fill_n(reinterpret_cast<float *>(d.data()), left.total(), 8.0f);
    std::fill_n(reinterpret_cast<float *>(gt.data()), left.total(), 8.0f);
    l.readOnly();
    r.readOnly();
    d.readOnly();
    gt.readOnly();
    binocle_named_image extra{"gt_disparity", imageOf(gt.data(), w, hgt, BINOCLE_PIXEL_FLOAT32, 4)};
    binocle_stereo_frame frame{};
    frame.struct_size = sizeof frame;
    frame.left = imageOf(l.data(), w, hgt, BINOCLE_PIXEL_GRAY8, 1);
    frame.right = imageOf(r.data(), w, hgt, BINOCLE_PIXEL_GRAY8, 1);
    frame.extras = &extra;
    frame.extra_count = 1;
    binocle_image disparity = imageOf(d.data(), w, hgt, BINOCLE_PIXEL_FLOAT32, 4);
    GuardedCloud cloud(500);
    binocle_eval_input in{};
    in.struct_size = sizeof in;
    in.frame = &frame;
    in.rectified_left = &frame.left;
    in.rectified_right = &frame.right;
    in.disparity = &disparity;
    in.cloud = &cloud.cloud;
    in.rig_yaml = "name: plugin-check\n";
    host.recorder.metrics.clear();
    const int32_t rc = api->evaluate(h, &in);
    expectMessage("evaluate", rc, api->last_error(h));
    if (rc != BINOCLE_OK) throw CaseFailure{std::string("\x01") + codeText(rc, api->last_error(h))};
    return host.recorder.metrics;
}

void evaluatorCases(Battery &b) {
    auto api = reinterpret_cast<const binocle_evaluator_api *>(b.record.table);
    const ParamValues &params = b.params;
    b.run("create_destroy", [&] { return createDestroyCycles<binocle_evaluator_api, binocle_evaluator>(api, params); });
    // An evaluator may refuse a synthetic frame (no calibration, no metadata): that is
    // fine when it says why with a code; the determinism case then has nothing to compare.
    auto evaluateOrRefusal = [&](binocle_evaluator *h, HostBlock &host, std::string &refusal) {
        try {
            return evaluated(api, h, host);
        } catch (const CaseFailure &f) {
            if (f.message.empty() || f.message[0] != '\x01') throw;
            refusal = f.message.substr(1);
            return std::vector<std::pair<std::string, double>>{};
        }
    };
    b.run("evaluate_in_host_buffers", [&] {
        HostBlock host;
        auto *h = createOrFail<binocle_evaluator_api, binocle_evaluator>(api, params, host);
        std::string refusal;
        const auto figures = evaluateOrRefusal(h, host, refusal);
        if (api->finish) {
            const int32_t rc = api->finish(h);
            expectMessage("finish", rc, api->last_error(h));
        }
        api->destroy(h);
        if (!refusal.empty()) return pass("refused the synthetic frame with a code: " + refusal);
        return pass(std::to_string(figures.size()) + " figures reported; inputs left untouched");
    });
    b.run("determinism", [&] {
        HostBlock ha, hb;
        auto *a = createOrFail<binocle_evaluator_api, binocle_evaluator>(api, params, ha);
        auto *c = createOrFail<binocle_evaluator_api, binocle_evaluator>(api, params, hb);
        std::string refusal;
        const auto f1 = evaluateOrRefusal(a, ha, refusal);
        if (!refusal.empty()) return skip("the synthetic frame is refused (" + refusal + ")");
        const auto f2 = evaluateOrRefusal(c, hb, refusal);
        if (f1 != f2) fail("two instances with the same settings report different figures for the same frame");
        api->destroy(a);
        api->destroy(c);
        return pass(std::to_string(f1.size()) + " identical figures from two instances");
    });
}

std::string xmlEscape(const std::string &s) {
    std::string out;
    for (char c : s) {
        switch (c) {
        case '&': out += "&amp;"; break;
        case '<': out += "&lt;"; break;
        case '>': out += "&gt;"; break;
        case '"': out += "&quot;"; break;
        case '\'': out += "&apos;"; break;
        default:
            if (static_cast<unsigned char>(c) < 0x20 && c != '\n' && c != '\t') out += ' ';
            else out += c;
        }
    }
    return out;
}

} // namespace

ConformanceReport checkPlugin(const ConformanceOptions &options) {
    ConformanceReport report;
    PluginHost finder(options.searchPath.empty() ? PluginHost::defaultSearchPath() : options.searchPath);
    std::string path = options.plugin;
    const bool isFile = path.find('/') != std::string::npos || (path.size() > 3 && path.compare(path.size() - 3, 3, ".so") == 0);
    if (!isFile) {
        path = finder.locate(options.plugin);
        if (path.empty()) {
            std::string why = "no file binocle_" + options.plugin + ".so in the search path (";
            for (size_t i = 0; i < finder.searchPath().size(); ++i) why += (i ? ":" : "") + finder.searchPath()[i];
            why += ")";
            for (const auto &r : finder.refused()) why += "; " + r.path + " refused: " + r.reason;
            throw Error(why);
        }
    } else {
        std::error_code ec;
        if (!fs::exists(path, ec)) throw Error("plugin file " + path + " does not exist");
        path = fs::weakly_canonical(path, ec).string();
    }
    report.path = path;
    report.plugin = fs::path(path).stem().string();

    // 1. The file, opened in a child first: its code runs at load.
    ConformanceCase load{"load", Status::Passed, "", 0};
    const auto t0 = Clock::now();
    const auto refusals = examineInChildren({path}, std::min(options.case_timeout_ms, 5000));
    PluginHost host(std::vector<std::string>{});
    const PluginRecord *record = nullptr;
    if (auto it = refusals.find(path); it != refusals.end()) {
        load.status = Status::Failed;
        load.message = it->second;
    } else {
        try {
            record = &host.load(path);
            load.message = "opened with RTLD_NOW; ABI " + std::to_string(record->abi_version) + ", API " +
                           std::to_string(record->api_version);
        } catch (const std::exception &e) {
            load.status = Status::Failed;
            load.message = e.what();
        }
    }
    load.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    report.cases.push_back(load);
    if (!record) return report;
    report.plugin = record->name;
    report.kind = kindName(record->kind);

    // 2. The table and its settings (what load checks, said in full).
    ConformanceCase table{"table", Status::Passed, "", 0};
    std::ostringstream facts;
    facts << report.kind << " '" << record->name << "' " << record->version << ", table " << record->table->struct_size
          << " bytes (API 1 needs " << leastTableSize(record->kind, 1) << ")";
    table.message = facts.str();
    if (record->version.empty() || record->description.empty()) {
        table.status = Status::Failed;
        table.message = "the header's version or description is empty (binocle plugins shows them)";
    }
    report.cases.push_back(table);
    ConformanceCase settings{"settings", Status::Passed, "", 0};
    const auto descs = record->params();
    std::vector<std::string> noHelp;
    for (const auto &d : descs)
        if (!d.help || !*d.help) noHelp.emplace_back(d.name);
    if (!noHelp.empty()) {
        settings.status = Status::Failed;
        settings.message = "settings without help text (plugins --verbose shows it):";
        for (const auto &n : noHelp) settings.message += " " + n;
    } else {
        settings.message = std::to_string(descs.size()) + " settings: unique names, valid defaults, help text";
    }
    report.cases.push_back(settings);

    // 3. Settings for create: defaults, with --set on top.
    ParamValues params;
    std::string missing;
    try {
        YAML::Node block(YAML::NodeType::Map);
        for (const auto &s : options.settings) applyOverride(block, Override::parse(s));
        std::error_code ec;
        params = resolveParams(*record, block, record->name, "(plugin-check --set)", fs::current_path(ec).string());
    } catch (const Error &e) {
        missing = e.what();
    }
    std::vector<ConformanceCase> cases;
    Battery battery{*record, params, options.case_timeout_ms, cases, ""};
    if (!missing.empty()) battery.skipAll = "cannot create an instance: " + missing + " (give settings with --set KEY=VALUE)";
    switch (record->kind) {
    case BINOCLE_KIND_MATCHER: matcherCases(battery); break;
    case BINOCLE_KIND_STEREO_SOURCE: sourceCases(battery); break;
    case BINOCLE_KIND_CLOUD_TRANSFORM: transformCases(battery); break;
    case BINOCLE_KIND_EVALUATOR: evaluatorCases(battery); break;
    default: break;
    }
    report.cases.insert(report.cases.end(), cases.begin(), cases.end());
    return report;
}

std::string junitXml(const ConformanceReport &r) {
    std::ostringstream os;
    double total = 0;
    for (const auto &c : r.cases) total += c.seconds;
    const std::string classname = "plugin_check." + (r.kind.empty() ? std::string("unknown") : r.kind) + "." + r.plugin;
    os << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
    os << "<testsuites tests=\"" << r.cases.size() << "\" failures=\"" << r.count(Status::Failed) << "\" skipped=\""
       << r.count(Status::Skipped) << "\">\n";
    os << "  <testsuite name=\"" << xmlEscape(classname) << "\" tests=\"" << r.cases.size() << "\" failures=\""
       << r.count(Status::Failed) << "\" errors=\"0\" skipped=\"" << r.count(Status::Skipped) << "\" time=\"" << total << "\">\n";
    os << "    <properties><property name=\"file\" value=\"" << xmlEscape(r.path) << "\"/></properties>\n";
    for (const auto &c : r.cases) {
        os << "    <testcase classname=\"" << xmlEscape(classname) << "\" name=\"" << xmlEscape(c.name) << "\" time=\"" << c.seconds << "\"";
        if (c.status == Status::Passed) {
            os << ">";
            if (!c.message.empty()) os << "<system-out>" << xmlEscape(c.message) << "</system-out>";
            os << "</testcase>\n";
        } else if (c.status == Status::Failed) {
            os << "><failure message=\"" << xmlEscape(c.message) << "\"/></testcase>\n";
        } else {
            os << "><skipped message=\"" << xmlEscape(c.message) << "\"/></testcase>\n";
        }
    }
    os << "  </testsuite>\n</testsuites>\n";
    return os.str();
}

} // namespace binocle

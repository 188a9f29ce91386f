// SPDX-License-Identifier: MIT
// The conformance kit's shared parts: a case in a child process with a deadline, the
// recording host, guard-paged memory, synthetic pairs and clouds.
#include "conformance/kit.hpp"

#include "host/child_process.hpp"

#include <algorithm>
#include <csignal>
#include <spdlog/spdlog.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>

namespace binocle::conformance {

ConformanceCase runCase(const std::string &name, int32_t timeout_ms, const std::function<Outcome()> &body) {
    ConformanceCase c;
    c.name = name;
    DeadlineChild::End end;
    try {
        end = DeadlineChild::run(
            [&] {
                Outcome o;
                try {
                    o = body();
                } catch (const CaseFailure &f) {
                    o = {Status::Failed, f.message};
                } catch (const std::exception &e) {
                    o = {Status::Failed, e.what()};
                }
                return std::string(1, "PFS"[static_cast<int>(o.status)]) + o.message;
            },
            timeout_ms);
    } catch (const std::exception &e) {
        c.status = Status::Failed;
        c.message = std::string("cannot run the case: ") + e.what();
        return c;
    }
    c.seconds = end.seconds;
    if (end.timedOut) {
        c.status = Status::Failed;
        c.message = "did not finish within " + std::to_string(timeout_ms) + " ms (a call hangs?); killed";
    } else if (WIFSIGNALED(end.status) || end.output.empty()) {
        c.status = Status::Failed;
        c.message = "crashed: " + describeExit(end.status);
        if (WIFSIGNALED(end.status) && WTERMSIG(end.status) == SIGABRT)
            c.message += " (an exception that crossed the ABI, or an assertion, ends this way)";
    } else {
        c.status = end.output[0] == 'P' ? Status::Passed : end.output[0] == 'S' ? Status::Skipped : Status::Failed;
        c.message = end.output.substr(1);
    }
    return c;
}

void Battery::run(const std::string &name, const std::function<Outcome()> &body) {
    if (!skipAll.empty()) {
        cases.push_back({name, Status::Skipped, skipAll, 0});
        return;
    }
    cases.push_back(runCase(name, timeout_ms, body));
}

// ---- Host services -----------------------------------------------------------------------------

namespace {

void recLog(void *, int32_t level, const char *message) {
    if (level >= BINOCLE_LOG_WARNING) spdlog::debug("plugin says: {}", message ? message : "");
}
void recMetric(void *ctx, const char *name, double value, const char *) {
    static_cast<Recorder *>(ctx)->metrics.emplace_back(name ? name : "", value);
}
void recText(void *ctx, const char *name, const char *text) {
    static_cast<Recorder *>(ctx)->texts.emplace_back(name ? name : "", text ? text : "");
}

} // namespace

HostBlock::HostBlock() {
    host.struct_size = sizeof(binocle_host);
    host.context = &recorder;
    host.log = &recLog;
    host.report_metric = &recMetric;
    host.report_text = &recText;
}

std::string codeText(int32_t rc, const char *message) {
    std::string s = resultName(rc);
    if (message && *message) s += ": " + std::string(message);
    return s;
}

void expectMessage(const char *call, int32_t rc, const char *message) {
    if (rc != BINOCLE_OK && (!message || !*message))
        fail(std::string(call) + " returned " + resultName(rc) + " but last_error gives no message");
}

// ---- Memory with guard pages -------------------------------------------------------------------

Guarded::Guarded(size_t bytes) : bytes_(std::max<size_t>(bytes, 1)) {
    page_ = static_cast<size_t>(::sysconf(_SC_PAGESIZE));
    span_ = (bytes_ + page_ - 1) / page_ * page_;
    void *p = ::mmap(nullptr, span_ + 2 * page_, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (p == MAP_FAILED) throw Error("cannot map guarded memory");
    base_ = static_cast<uint8_t *>(p);
    ::mprotect(base_, page_, PROT_NONE);
    ::mprotect(base_ + page_ + span_, page_, PROT_NONE);
    data_ = base_ + page_ + (span_ - bytes_);
}

Guarded::~Guarded() { ::munmap(base_, span_ + 2 * page_); }

void Guarded::readOnly() { ::mprotect(base_ + page_, span_, PROT_READ); }

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

GuardedCloud::GuardedCloud(int64_t n)
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

} // namespace binocle::conformance

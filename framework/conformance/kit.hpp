// SPDX-License-Identifier: MIT
// The conformance kit's parts every family of cases uses (one file per family,
// cases_<kind>.cpp, as lc-compliance has): outcomes, a case in a child process with a
// deadline, a host that records what a plugin reports, memory with guard pages, and the
// battery that runs a kind's cases. Internal to conformance/.
#pragma once

#include "conformance/conformance.hpp"
#include "host/plugin_host.hpp"

#include <binocle/abi.h>

#include <functional>
#include <opencv2/core.hpp>
#include <string>
#include <utility>
#include <vector>

namespace binocle::conformance {

using Status = ConformanceCase::Status;

struct Outcome {
    Status status = Status::Passed;
    std::string message;
};

inline Outcome pass(std::string m = "") { return {Status::Passed, std::move(m)}; }
inline Outcome skip(std::string m) { return {Status::Skipped, std::move(m)}; }

// A failed expectation inside a case: ends it as failed with the message.
struct CaseFailure {
    std::string message;
};
[[noreturn]] inline void fail(const std::string &m) { throw CaseFailure{m}; }

// Runs `body` in a child process with a deadline; a crash or a timeout is a failure
// naming the signal or the time.
ConformanceCase runCase(const std::string &name, int32_t timeout_ms, const std::function<Outcome()> &body);

// ---- Host services for the instances under test ----------------------------------------------

struct Recorder {
    std::vector<std::pair<std::string, double>> metrics;
    std::vector<std::pair<std::string, std::string>> texts;
};

// A binocle_host whose figures and texts land in `recorder`.
struct HostBlock {
    Recorder recorder;
    binocle_host host{};
    HostBlock();
    HostBlock(const HostBlock &) = delete;
    HostBlock &operator=(const HostBlock &) = delete;
};

// "BINOCLE_ERR_IO: the plugin's message".
std::string codeText(int32_t rc, const char *message);
// A failed call must say why: a non-OK code with an empty last_error is a defect.
void expectMessage(const char *call, int32_t rc, const char *message);

// ---- Memory with guard pages -----------------------------------------------------------------

// `bytes` of memory whose end abuts an inaccessible page, with another one before the
// first page: a write or read past either end is a SIGSEGV in the case's child.
class Guarded {
public:
    explicit Guarded(size_t bytes);
    ~Guarded();
    Guarded(const Guarded &) = delete;
    Guarded &operator=(const Guarded &) = delete;
    uint8_t *data() { return data_; }
    // Inputs are the host's: a plugin may read them, never write.
    void readOnly();

private:
    size_t bytes_, page_ = 4096, span_ = 0;
    uint8_t *base_ = nullptr, *data_ = nullptr;
};

// A textured pair: right is left shifted by 8 px, so a matcher finds disparity 8.
void texturedPair(cv::Mat &left, cv::Mat &right, int width, int height, int type);
binocle_image imageOf(void *data, int width, int height, int32_t format, int bpp);

// A cloud of n points in front of the camera, in guarded memory.
struct GuardedCloud {
    explicit GuardedCloud(int64_t n);
    Guarded xyz, rgb, pixel;
    binocle_cloud cloud{};
};

// ---- The battery ---------------------------------------------------------------------------------

struct Battery {
    const PluginRecord &record;
    const ParamValues &params;
    int32_t timeout_ms;
    std::vector<ConformanceCase> &cases;
    std::string skipAll; // set when instances cannot be made (a device is missing ...)

    // Runs a case in a child, or records it as skipped with skipAll's reason.
    void run(const std::string &name, const std::function<Outcome()> &body);
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

// A kind's family of cases on the plugin's table as `Api` (binocle_matcher_api ...), whose
// instances are `Handle`s made with the battery's settings.
template <class Api, class Handle>
struct Family {
    Battery &battery;
    const Api *api;

    explicit Family(Battery &b) : battery(b), api(reinterpret_cast<const Api *>(b.record.table)) {}

    // An instance whose figures and texts land in `host`; a failed create fails the case.
    Handle *create(HostBlock &host) const { return createOrFail<Api, Handle>(api, battery.params, host); }

    // The create_destroy case (createDestroyCycles), which every family runs.
    void createDestroyCase() const {
        battery.run("create_destroy", [this] { return createDestroyCycles<Api, Handle>(api, battery.params); });
    }

    // A case on one new instance: `body(h, host)` gives the outcome, and the instance is
    // destroyed once the body has returned (a failed case ends its child process as it is).
    template <class Body>
    void instanceCase(const std::string &name, Body body) const {
        battery.run(name, [this, body] {
            HostBlock host;
            Handle *h = create(host);
            Outcome outcome = body(h, host);
            api->destroy(h);
            return outcome;
        });
    }
};

} // namespace binocle::conformance

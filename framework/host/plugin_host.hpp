// SPDX-License-Identifier: MIT
// The plugin host: finds plugin files (binocle_<name>.so) on a safe search path, loads
// them with Boost.DLL (RTLD_NOW), checks their ABI and settings tables before calling
// anything else, and wraps their C tables in C++ objects that throw
// binocle::PluginError with the plugin's own message when a call fails. Any plugin may
// run in a helper process instead (IsolationOptions, host/isolation.hpp).
#pragma once

#include "core/error.hpp"

#include <binocle/abi.h>
#include <binocle/plugin.hpp>

#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace boost::dll {
class shared_library;
}

namespace binocle {

const char *kindName(int32_t kind);    // "source", "matcher", "transform", "evaluator"
const char *resultName(int32_t code);  // "BINOCLE_ERR_TIMEOUT" ...
using sdk::bytesPerPixel; // of a BINOCLE_PIXEL_* format, 0 when unknown: the SDK's (binocle/plugin.hpp)

// A plugin file that was accepted.
struct PluginRecord {
    std::string path;
    std::string name, version, description;
    int32_t kind = 0;
    uint32_t abi_version = 0, api_version = 0;
    // The host's own full-size copy of the plugin's table: the bytes the plugin declared
    // (header.struct_size), zeros after them, so that an entry a plugin built against an
    // older API lacks reads as NULL (absent) and one a newer plugin appended is never read.
    const binocle_plugin_header *table = nullptr;
    std::shared_ptr<const void> tableStorage;
    std::shared_ptr<boost::dll::shared_library> library; // keeps the code loaded
    // Read by a helper process (PluginHost::describe): header and settings table only, no
    // library and no entry points here; instances of it run in helper processes only.
    bool described = false;
    std::vector<binocle_param_desc> params() const;
};

// The least table size the host accepts for a kind at an API version: the end of the
// last entry that version defines. Frozen per version; 0 for an unknown kind or version.
size_t leastTableSize(int32_t kind, uint32_t api_version);

// Why a settings table is unusable ("setting #2 'window_px': default '4' is not odd"),
// or "" when every setting has a valid name, type and default, and names are unique.
std::string settingsTableProblem(const binocle_param_desc *params, int32_t count);

// A file that looked like a plugin and was refused, with why.
struct Refusal {
    std::string path;
    std::string reason;
};

// How a rig runs a plugin: in the process (default), or in a helper process of its own
// (`isolation: process` in the rig block) that may crash or hang without taking Binocle
// down; every kind of plugin honours it.
struct IsolationOptions {
    bool process = false;
    int32_t call_timeout_ms = 0; // 0: no watchdog
    bool restart = false;        // restart a helper that crashed or hung
    int32_t max_restarts = 3;
};

// Settings as the plugin receives them; owns the strings.
class ParamValues {
public:
    void setIsolation(const IsolationOptions &o) { isolation_ = o; }
    const IsolationOptions &isolation() const { return isolation_; }
    void setBool(const std::string &name, bool v, bool isExplicit = true);
    void setInt(const std::string &name, int64_t v, bool isExplicit = true);
    void setDouble(const std::string &name, double v, bool isExplicit = true);
    // STRING, ENUM, PATH, YAML, lists: `type` is the desc's type.
    void setText(const std::string &name, int32_t type, const std::string &v, bool isExplicit = true);
    const binocle_param *data() const;
    int32_t size() const;
    const binocle_param *find(const std::string &name) const;

private:
    IsolationOptions isolation_;
    std::vector<binocle_param> values_;
    std::vector<std::shared_ptr<std::string>> strings_; // shared: copies keep pointers valid
    binocle_param &slot(const std::string &name);
};

// Where figures and logs reported by a plugin instance go.
struct HostSink {
    std::function<void(int32_t level, const std::string &)> log;
    std::function<void(const std::string &name, double value, const std::string &unit)> metric;
    std::function<void(const std::string &name, const std::string &text)> text;
};

// How an instance runs: in this process, or behind a proxy that talks to its helper
// process (host/isolation.hpp). Chosen once, when the instance is made; each kind's
// wrapper holds one implementation of its kind's interface (kind_<name>.cpp).
class InstanceImpl {
public:
    virtual ~InstanceImpl() = default;
    virtual bool isolated() const { return false; }
    virtual int32_t restarts() const { return 0; }
    virtual int64_t lostCalls() const { return 0; }
};

// Common part of the instance wrappers.
class PluginInstanceBase {
public:
    // One wrapper per plugin instance: a copy would destroy the instance twice.
    PluginInstanceBase(const PluginInstanceBase &) = delete;
    PluginInstanceBase &operator=(const PluginInstanceBase &) = delete;
    const PluginRecord &record() const { return record_; }
    // Replaces where this instance's metrics and logs go (default: log to stderr).
    void setSink(HostSink sink);
    // True when the plugin runs in a helper process (`isolation: process`).
    bool isolated() const { return running_ && running_->isolated(); }
    // Restarts of its helper process, and calls whose result they lost (0 in process).
    int32_t restarts() const { return running_ ? running_->restarts() : 0; }
    int64_t lostCalls() const { return running_ ? running_->lostCalls() : 0; }

protected:
    explicit PluginInstanceBase(const PluginRecord &record);
    // Instances of a described record run isolated whatever the rig says.
    static bool runsIsolated(const PluginRecord &record, const ParamValues &params);
    // The implementation for this instance: InProcess(record, params, host) or, when it
    // runs isolated, Proxy(record, params, host). The one place the choice is made.
    template <class Impl, class InProcess, class Proxy>
    std::unique_ptr<Impl> choose(const PluginRecord &record, const ParamValues &params) {
        std::unique_ptr<Impl> impl;
        if (runsIsolated(record, params)) impl = std::make_unique<Proxy>(record, params, host_);
        else impl = std::make_unique<InProcess>(record, params, host_);
        running_ = impl.get();
        return impl;
    }
    PluginRecord record_;
    std::shared_ptr<binocle_host> host_; // deleted with its sink context
    const InstanceImpl *running_ = nullptr; // the derived wrapper's implementation
};

// A frame lent by a source; released when this object dies. Views are zero-copy.
class LentFrame {
public:
    LentFrame(std::shared_ptr<void> keep, const binocle_source_api *api, binocle_source *src,
              const binocle_stereo_frame &f);
    // A frame whose pixels `keep` holds (the copy of an isolated source's frame): nothing
    // to give back but `keep`.
    LentFrame(std::shared_ptr<void> keep, const binocle_stereo_frame &f);
    ~LentFrame();
    LentFrame(const LentFrame &) = delete;
    LentFrame &operator=(const LentFrame &) = delete;
    const binocle_stereo_frame &raw() const { return frame_; }
    cv::Mat left() const;  // view, no copy
    cv::Mat right() const; // view, no copy
    // Extra plane by name ("gt_disparity"), or an empty Mat.
    cv::Mat extra(const std::string &name) const;
    std::string metadata() const { return frame_.metadata ? frame_.metadata : ""; }

private:
    std::shared_ptr<void> keep_;
    const binocle_source_api *api_;
    binocle_source *src_;
    binocle_stereo_frame frame_;
};

class Source : public PluginInstanceBase {
public:
    Source(const PluginRecord &record, const ParamValues &params);
    ~Source();
    void start();
    void stop();
    // nullptr at end of stream; throws on any other failure (timeouts included).
    std::unique_ptr<LentFrame> grab(int32_t timeout_ms = -1);
    std::string calibration(); // empty if none
    std::string statistics();
    static std::string enumerateDevices(const PluginRecord &record);

    class Impl;

private:
    std::unique_ptr<Impl> impl_;
};

// A plane a matcher attached to its disparity (matcher.h: extras), e.g.
// "disparity_filled": the host's copy, of the disparity's size (CV_8U, CV_16U or CV_32F).
struct NamedPlane {
    std::string name;
    cv::Mat image;
};

class Matcher : public PluginInstanceBase {
public:
    // In this process, or in a helper process when params.isolation().process.
    Matcher(const PluginRecord &record, const ParamValues &params);
    ~Matcher();
    // Returns a CV_32F disparity (host-allocated), invalid pixels <= 0. Disparities that
    // are not finite or exceed the image width are made invalid and counted.
    cv::Mat compute(const cv::Mat &left, const cv::Mat &right);
    // The same into `disparity`, whose buffer is reused when it has the size already.
    void compute(const cv::Mat &left, const cv::Mat &right, cv::Mat &disparity);
    std::pair<int32_t, int32_t> disparityRange();
    // Runs the plugin's compute into `disparity` (CV_32F, left's size), checking that it
    // kept the host's image description; no clean-up of the values.
    void computeInto(const cv::Mat &left, const cv::Mat &right, cv::Mat &disparity);
    // Disparities made invalid so far because they were not finite or absurd.
    uint64_t invalidatedDisparities() const { return invalidated_; }
    // The planes the plugin attached to the last compute's disparity (none when its table
    // has no extras entry, or after a failed compute): new buffers each compute, so a
    // copy of the list stays valid.
    const std::vector<NamedPlane> &extras() const { return extras_; }

    class Impl;

private:
    std::unique_ptr<Impl> impl_;
    std::vector<NamedPlane> extras_;
    uint64_t invalidated_ = 0;
    bool warnedInvalid_ = false;
};

class CloudTransform : public PluginInstanceBase {
public:
    CloudTransform(const PluginRecord &record, const ParamValues &params);
    ~CloudTransform();
    void apply(binocle_cloud &cloud);

    class Impl;

private:
    std::unique_ptr<Impl> impl_;
};

class Evaluator : public PluginInstanceBase {
public:
    Evaluator(const PluginRecord &record, const ParamValues &params, HostSink sink);
    ~Evaluator();
    void evaluate(const binocle_eval_input &input);
    void finish();

    class Impl;

private:
    std::unique_ptr<Impl> impl_;
};

enum class ScanMode {
    InProcess, // open every file in this process (a crashing constructor takes it down)
    Isolated   // examine each file in a short-lived child first; open only those that pass
};

class PluginHost {
public:
    // $BINOCLE_PLUGIN_PATH (':'-separated), then <prefix>/lib/binocle/plugins, the prefix
    // of host/install_prefix.hpp (the running executable's, or the one a program named,
    // e.g. the Python module); the build tree mirrors that layout. No path is compiled in.
    static std::vector<std::string> defaultSearchPath();

    explicit PluginHost(std::vector<std::string> searchPath = defaultSearchPath());
    ~PluginHost();

    // Looks at every binocle_*.so in the search path (first folder wins for a file name).
    // Isolated: a file whose code crashes or hangs at load (child_timeout_ms) is refused
    // with the signal or the timeout, and the scan goes on.
    void scan(ScanMode mode = ScanMode::InProcess, int32_t child_timeout_ms = 2000) const;
    // Loads one file; throws binocle::Error naming the file and the reason.
    const PluginRecord &load(const std::string &path);

    // Records stay where they are while more plugins are opened (a deque).
    const std::deque<PluginRecord> &plugins() const { return plugins_; }
    const std::vector<Refusal> &refused() const { return refused_; }
    const std::vector<std::string> &searchPath() const { return searchPath_; }
    // Among the files opened so far; nullptr if absent (or of another kind when kind != 0).
    const PluginRecord *find(const std::string &name, int32_t kind = 0) const;
    // Like find, but opens binocle_<name>.so from the first folder of the search path that
    // holds it when it is not open yet, and no other file: a rig opens only what it names.
    // A refusal lands in refused(). The host is a cache of opened files, hence const.
    const PluginRecord *lookup(const std::string &name, int32_t kind = 0) const;
    // The file binocle_<name>.so in the first safe folder of the search path that holds
    // one, without opening it; "" when there is none.
    std::string locate(const std::string &name) const;
    // Throws Error "no <kind> plugin named 'x' (found: a, b, c)"; opens the file like lookup.
    const PluginRecord &require(const std::string &name, int32_t kind) const;
    // Like lookup for a plugin that runs isolated: binocle_<name>.so is read by a helper
    // process (describeInHelper, at most timeout_ms), never opened here, so none of its
    // code runs in this process. A refusal (the signal of a crash, a timeout) lands in
    // refused(). The record is described (no library).
    const PluginRecord *describe(const std::string &name, int32_t kind = 0, int32_t timeout_ms = 15000) const;
    // The records describe() made.
    const std::deque<PluginRecord> &described() const { return described_; }

private:
    std::vector<std::string> searchPath_;
    mutable std::deque<PluginRecord> plugins_;
    mutable std::deque<PluginRecord> described_;
    mutable std::vector<Refusal> refused_;
    const PluginRecord &inspect(const std::string &path) const; // throws with reason
    // Folders of the search path that are safe to load from; unsafe ones are refused once.
    std::vector<std::string> safeFolders() const;
    bool known(const std::string &canonical) const;
};

} // namespace binocle

// SPDX-License-Identifier: MIT
// The plugin host: finds plugin files, loads them with Boost.DLL, checks their ABI
// before anything else, and wraps their C tables in C++ objects that throw
// binocle::PluginError with the plugin's own message when a call fails.
#pragma once

#include "core/error.hpp"

#include <binocle/abi.h>

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

// A plugin file that was accepted.
struct PluginRecord {
    std::string path;
    std::string name, version, description;
    int32_t kind = 0;
    uint32_t abi_version = 0, api_version = 0;
    const binocle_plugin_header *table = nullptr;
    std::shared_ptr<boost::dll::shared_library> library; // keeps the code loaded
    std::vector<binocle_param_desc> params() const;
};

// A file that looked like a plugin and was refused, with why.
struct Refusal {
    std::string path;
    std::string reason;
};

// Settings as the plugin receives them; owns the strings.
class ParamValues {
public:
    void setBool(const std::string &name, bool v, bool isExplicit = true);
    void setInt(const std::string &name, int64_t v, bool isExplicit = true);
    void setDouble(const std::string &name, double v, bool isExplicit = true);
    // STRING, ENUM, PATH, YAML, lists: `type` is the desc's type.
    void setText(const std::string &name, int32_t type, const std::string &v, bool isExplicit = true);
    const binocle_param *data() const;
    int32_t size() const;
    const binocle_param *find(const std::string &name) const;

private:
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

// Common part of the instance wrappers.
class PluginInstanceBase {
public:
    // One wrapper per plugin instance: a copy would destroy the instance twice.
    PluginInstanceBase(const PluginInstanceBase &) = delete;
    PluginInstanceBase &operator=(const PluginInstanceBase &) = delete;
    const PluginRecord &record() const { return record_; }
    // Replaces where this instance's metrics and logs go (default: log to stderr).
    void setSink(HostSink sink);

protected:
    explicit PluginInstanceBase(const PluginRecord &record);
    // Throws PluginError "<kind> plugin '<name>' (<path>): <what> failed (<code>): <message>".
    [[noreturn]] void fail(const std::string &what, int32_t code, const char *message) const;
    PluginRecord record_;
    std::shared_ptr<binocle_host> host_; // deleted with its sink context
};

// A frame lent by a source; released when this object dies. Views are zero-copy.
class LentFrame {
public:
    LentFrame(std::shared_ptr<void> keep, const binocle_source_api *api, binocle_source *src,
              const binocle_stereo_frame &f);
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

private:
    const binocle_source_api *api_;
    std::shared_ptr<binocle_source> handle_;
};

class Matcher : public PluginInstanceBase {
public:
    Matcher(const PluginRecord &record, const ParamValues &params);
    ~Matcher();
    // Returns a CV_32F disparity (host-allocated), invalid pixels <= 0.
    cv::Mat compute(const cv::Mat &left, const cv::Mat &right);
    // The same into `disparity`, whose buffer is reused when it has the size already.
    void compute(const cv::Mat &left, const cv::Mat &right, cv::Mat &disparity);
    std::pair<int32_t, int32_t> disparityRange();

private:
    const binocle_matcher_api *api_;
    binocle_matcher *handle_ = nullptr;
};

class CloudTransform : public PluginInstanceBase {
public:
    CloudTransform(const PluginRecord &record, const ParamValues &params);
    ~CloudTransform();
    void apply(binocle_cloud &cloud);

private:
    const binocle_cloud_transform_api *api_;
    binocle_cloud_transform *handle_ = nullptr;
};

class Evaluator : public PluginInstanceBase {
public:
    Evaluator(const PluginRecord &record, const ParamValues &params, HostSink sink);
    ~Evaluator();
    void evaluate(const binocle_eval_input &input);
    void finish();

private:
    const binocle_evaluator_api *api_;
    binocle_evaluator *handle_ = nullptr;
};

class PluginHost {
public:
    // $BINOCLE_PLUGIN_PATH (':'-separated), then <prefix>/lib/binocle/plugins next to
    // the running executable, then the build tree's plugin folder.
    static std::vector<std::string> defaultSearchPath();

    explicit PluginHost(std::vector<std::string> searchPath = defaultSearchPath());
    ~PluginHost();

    // Looks at every binocle_*.so in the search path (first folder wins for a name).
    void scan();
    // Loads one file; throws binocle::Error naming the file and the reason.
    const PluginRecord &load(const std::string &path);

    const std::vector<PluginRecord> &plugins() const { return plugins_; }
    const std::vector<Refusal> &refused() const { return refused_; }
    const std::vector<std::string> &searchPath() const { return searchPath_; }
    // nullptr if absent (or of another kind when kind != 0).
    const PluginRecord *find(const std::string &name, int32_t kind = 0) const;
    // Throws Error "no <kind> plugin named 'x' (found: a, b, c)".
    const PluginRecord &require(const std::string &name, int32_t kind) const;

private:
    std::vector<std::string> searchPath_;
    std::vector<PluginRecord> plugins_;
    std::vector<Refusal> refused_;
    const PluginRecord &inspect(const std::string &path); // throws with reason
};

} // namespace binocle

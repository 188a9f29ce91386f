// SPDX-License-Identifier: MIT
// What the kinds' implementations share (kind_<name>.cpp): the error of a failed call,
// the checks of images a plugin hands back, and views between cv::Mat and binocle_image.
// Internal to host/.
#pragma once

#include "host/plugin_record.hpp"
#include "host/plugin_settings.hpp"

#include <binocle/abi.h>

#include <memory>
#include <opencv2/core.hpp>
#include <string>

namespace binocle {

// Throws PluginError "<kind> plugin '<name>' (<path>): <what> failed (<code>): <message>".
[[noreturn]] void failCall(const PluginRecord &record, const std::string &what, int32_t code, const char *message);

// A binocle_host that logs to stderr under the plugin's name (for calls without an instance).
std::shared_ptr<binocle_host> defaultHost(const std::string &plugin);

// "" when an image a plugin handed back is usable, else what is wrong with it.
std::string checkImage(const binocle_image &im, const char *what);
// "" when a lent frame is usable (images, extras), else what is wrong with it.
std::string checkFrame(const binocle_stereo_frame &f);
// A view of the image's pixels (no copy).
cv::Mat view(const binocle_image &im);
binocle_image wrap(const cv::Mat &m, int32_t format);
// BINOCLE_PIXEL_* of a Mat's type; throws Error for a type that cannot cross the ABI.
int32_t formatOf(const cv::Mat &m);

// A plugin instance made in this process: create in the constructor (a failure throws
// PluginError with the plugin's message), destroy in the destructor.
template <class Api, class Handle>
class Created {
public:
    Created(const PluginRecord &record, const ParamValues &params, const binocle_host *host)
        : record_(record), api_(reinterpret_cast<const Api *>(record.table)) {
        const int32_t rc = api_->create(params.data(), params.size(), host, &handle_);
        if (rc != BINOCLE_OK || !handle_) failCall(record_, "create", rc ? rc : BINOCLE_ERR_INTERNAL, api_->last_error(nullptr));
    }
    ~Created() {
        if (handle_) api_->destroy(handle_);
    }
    Created(const Created &) = delete;
    Created &operator=(const Created &) = delete;

protected:
    // Throws the PluginError of a call that returned `rc`, with the plugin's message.
    [[noreturn]] void failed(const char *what, int32_t rc) const { failCall(record_, what, rc, api_->last_error(handle_)); }
    const PluginRecord &record_;
    const Api *api_;
    Handle *handle_ = nullptr;
};

} // namespace binocle

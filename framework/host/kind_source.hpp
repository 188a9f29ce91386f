// SPDX-License-Identifier: MIT
// The stereo source kind's wrapper: a Source instance, in this process or in a helper
// process (kind_source.cpp).
#pragma once

#include "host/plugin_instance.hpp"
#include "host/lent_frame.hpp"

#include <memory>
#include <string>

namespace binocle {

class Source : public PluginInstanceBase {
public:
    Source(const PluginRecord &record, const ParamValues &params, const IsolationOptions &isolation = {});
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

} // namespace binocle

// SPDX-License-Identifier: MIT
// The evaluator kind's wrapper: an Evaluator instance, in this process or in a helper
// process (kind_evaluator.cpp).
#pragma once

#include "host/plugin_instance.hpp"

#include <memory>

namespace binocle {

class Evaluator : public PluginInstanceBase {
public:
    Evaluator(const PluginRecord &record, const ParamValues &params, HostSink sink, const IsolationOptions &isolation = {});
    ~Evaluator();
    void evaluate(const binocle_eval_input &input);
    void finish();

    class Impl;

private:
    std::unique_ptr<Impl> impl_;
};

} // namespace binocle

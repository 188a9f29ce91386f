// SPDX-License-Identifier: MIT
// The cloud transform kind's wrapper: a CloudTransform instance, in this process or in a
// helper process (kind_transform.cpp).
#pragma once

#include "host/plugin_instance.hpp"

#include <memory>

namespace binocle {

class CloudTransform : public PluginInstanceBase {
public:
    CloudTransform(const PluginRecord &record, const ParamValues &params, const IsolationOptions &isolation = {});
    ~CloudTransform();
    void apply(binocle_cloud &cloud);

    class Impl;

private:
    std::unique_ptr<Impl> impl_;
};

} // namespace binocle

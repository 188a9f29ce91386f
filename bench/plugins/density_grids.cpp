// SPDX-License-Identifier: MIT
// density_grids: a benchmark-only evaluator that bins the ground-frame cloud into the
// three density grids of the paper's program (base/method), the last step of the
// serial loop that bench_pipeline.cpp compares the pipeline with.
#include "method/density_grid.hpp"

#include <binocle/plugin.hpp>

namespace {

class DensityGrids : public binocle::sdk::Evaluator {
public:
    static std::vector<binocle_param_desc> parameters() { return {}; }
    DensityGrids(const binocle::sdk::CheckedParams &, binocle::sdk::Host &host) : host_(host) {}

    void evaluate(const binocle_eval_input &in) override {
        const binocle::method::DensityGrids g = binocle::method::binCloud(binocle::method::CloudView(*in.cloud), spec_);
        host_.metric("top_points", static_cast<double>(g.top.total()));
    }

private:
    binocle::sdk::Host &host_;
    binocle::method::GridSpec spec_;
};

} // namespace

BINOCLE_EXPORT_EVALUATOR(DensityGrids, "density_grids", "1.0.0", "benchmark: the three density grids of a ground-frame cloud")

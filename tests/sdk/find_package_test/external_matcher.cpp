// SPDX-License-Identifier: MIT
// external_matcher: a plugin built outside the Binocle tree with the installed SDK only;
// writes disparity_px wherever the left pixel is not black. Its constructor takes the raw
// `sdk::Params`, as plugins written before the SDK built their `CheckedParams` did: that
// form must keep compiling (with -Werror) and running. New plugins take
// `const sdk::CheckedParams &` (examples/census_matcher).
#include <binocle/plugin.hpp>
// The header-only helpers compile from the installed SDK alone, too.
#include <binocle/recording.hpp>
#include <binocle/text.hpp>

#include <cstdint>

namespace {

class ExternalMatcher : public binocle::sdk::Matcher {
public:
    static std::vector<binocle_param_desc> parameters() {
        return {binocle::sdk::Param::real("disparity_px", "6").min(0).unit("px").help("the disparity written")};
    }
    ExternalMatcher(const binocle::sdk::Params &p, binocle::sdk::Host &host) : d_(static_cast<float>(p.real("disparity_px"))) {
        host.info("external_matcher created");
    }
    void compute(const binocle_image &left, const binocle_image &, binocle_image &disparity) override {
        if (left.format != BINOCLE_PIXEL_GRAY8) throw binocle::sdk::Error(BINOCLE_ERR_UNSUPPORTED, "external_matcher: GRAY8 only");
        for (int32_t y = 0; y < left.height; ++y) {
            auto *in = static_cast<const uint8_t *>(left.data) + static_cast<size_t>(y) * left.stride_bytes;
            auto *out = reinterpret_cast<float *>(static_cast<uint8_t *>(disparity.data) + static_cast<size_t>(y) * disparity.stride_bytes);
            for (int32_t x = 0; x < left.width; ++x) out[x] = in[x] ? d_ : BINOCLE_INVALID_DISPARITY;
        }
    }
    std::pair<int32_t, int32_t> disparityRange() const override { return {0, 16}; }

private:
    float d_;
};

} // namespace

BINOCLE_EXPORT_MATCHER(ExternalMatcher, "external_matcher", "1.2.3", "built out of tree against the installed SDK")

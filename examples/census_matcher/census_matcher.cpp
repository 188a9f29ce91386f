// SPDX-License-Identifier: MIT
// census: a matcher with its own keys (not bm's): census transform over a square window,
// Hamming distance, winner takes all, optional left-right check. An example of a
// third-party plugin built against the installed SDK alone.
#include <binocle/plugin.hpp>

#include <cstdint>
#include <vector>

namespace {

using binocle::sdk::Error;
using binocle::sdk::Param;

class Census : public binocle::sdk::Matcher {
public:
    static std::vector<binocle_param_desc> parameters() {
        return {Param::integer("window_px", "5").min(3).max(7).odd().unit("px").help("side of the census window"),
                Param::integer("max_disparity_px", "64").min(8).max(256).multipleOf(8).unit("px")
                    .help("disparities searched: 0 .. max_disparity_px - 1"),
                Param::integer("max_hamming", "12").min(0).max(48).help("a best match differing in more bits is invalid"),
                Param::boolean("left_right_check", true).help("invalidate pixels whose right-to-left match disagrees by > 1 px")};
    }

    // `p` holds the settings checked against the table above (a key the rig leaves out
    // reads as its default): nothing of the table is restated here.
    Census(const binocle::sdk::CheckedParams &p, binocle::sdk::Host &)
        : window_(static_cast<int>(p.integer("window_px"))), maxDisparity_(static_cast<int>(p.integer("max_disparity_px"))),
          maxHamming_(static_cast<int>(p.integer("max_hamming"))), leftRight_(p.boolean("left_right_check")) {}

    void compute(const binocle_image &left, const binocle_image &right, binocle_image &disparity) override {
        if (left.format != right.format || left.width != right.width || left.height != right.height)
            throw Error(BINOCLE_ERR_INVALID_ARGUMENT, "census: left and right differ in size or format");
        if (left.format != BINOCLE_PIXEL_GRAY8 && left.format != BINOCLE_PIXEL_BGR8 && left.format != BINOCLE_PIXEL_RGB8)
            throw Error(BINOCLE_ERR_UNSUPPORTED, "census: images must be GRAY8, BGR8 or RGB8");
        const int w = left.width, h = left.height;
        const std::vector<uint64_t> cl = census(grey(left), w, h), cr = census(grey(right), w, h);
        std::vector<int> best(static_cast<size_t>(w) * h, -1), bestRight(static_cast<size_t>(w) * h, -1);
        match(cl, cr, w, h, +1, best);
        if (leftRight_) match(cr, cl, w, h, -1, bestRight);
        for (int y = 0; y < h; ++y) {
            auto *row = reinterpret_cast<float *>(static_cast<uint8_t *>(disparity.data) + static_cast<size_t>(y) * disparity.stride_bytes);
            for (int x = 0; x < w; ++x) {
                const int d = best[static_cast<size_t>(y) * w + x];
                bool ok = d > 0;
                if (ok && leftRight_) {
                    const int back = bestRight[static_cast<size_t>(y) * w + (x - d)];
                    ok = back >= 0 && (back - d <= 1 && d - back <= 1);
                }
                row[x] = ok ? static_cast<float>(d) : BINOCLE_INVALID_DISPARITY;
            }
        }
    }

    std::pair<int32_t, int32_t> disparityRange() const override { return {0, maxDisparity_}; }

private:
    static std::vector<uint8_t> grey(const binocle_image &im) {
        std::vector<uint8_t> g(static_cast<size_t>(im.width) * im.height);
        const int bpp = im.format == BINOCLE_PIXEL_GRAY8 ? 1 : 3;
        for (int y = 0; y < im.height; ++y) {
            const auto *row = static_cast<const uint8_t *>(im.data) + static_cast<size_t>(y) * im.stride_bytes;
            for (int x = 0; x < im.width; ++x) {
                const uint8_t *p = row + x * bpp;
                g[static_cast<size_t>(y) * im.width + x] = bpp == 1 ? p[0] : static_cast<uint8_t>((p[0] + 2 * p[1] + p[2]) / 4);
            }
        }
        return g;
    }

    // One bit per window neighbour: darker than the centre. Border pixels get 0.
    std::vector<uint64_t> census(const std::vector<uint8_t> &g, int w, int h) const {
        std::vector<uint64_t> c(g.size(), 0);
        const int r = window_ / 2;
        for (int y = r; y < h - r; ++y)
            for (int x = r; x < w - r; ++x) {
                const uint8_t centre = g[static_cast<size_t>(y) * w + x];
                uint64_t bits = 0;
                for (int dy = -r; dy <= r; ++dy)
                    for (int dx = -r; dx <= r; ++dx)
                        if (dx || dy) bits = (bits << 1) | (g[static_cast<size_t>(y + dy) * w + x + dx] < centre);
                c[static_cast<size_t>(y) * w + x] = bits;
            }
        return c;
    }

    // For every pixel of `from`, the disparity of the lowest Hamming distance in `to`
    // (sign +1: to is the right image, candidates at x - d), or -1.
    void match(const std::vector<uint64_t> &from, const std::vector<uint64_t> &to, int w, int h, int sign,
               std::vector<int> &out) const {
        const int r = window_ / 2;
        for (int y = r; y < h - r; ++y)
            for (int x = r; x < w - r; ++x) {
                int bestCost = 65, bestD = -1;
                for (int d = 0; d < maxDisparity_; ++d) {
                    const int xo = x - sign * d;
                    if (xo < r || xo >= w - r) break;
                    const int cost = __builtin_popcountll(from[static_cast<size_t>(y) * w + x] ^ to[static_cast<size_t>(y) * w + xo]);
                    if (cost < bestCost) bestCost = cost, bestD = d;
                }
                out[static_cast<size_t>(y) * w + x] = bestCost <= maxHamming_ ? bestD : -1;
            }
    }

    int window_, maxDisparity_, maxHamming_;
    bool leftRight_;
};

} // namespace

BINOCLE_EXPORT_MATCHER(Census, "census", "1.0.0", "census transform + Hamming distance, winner takes all (SDK example)")

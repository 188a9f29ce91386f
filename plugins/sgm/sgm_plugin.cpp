// SPDX-License-Identifier: MIT
// sgm: census + semi-global matching, a Matcher plugin built on the Binocle SDK alone
// (binocle/plugin.hpp) and OpenCV. The settings, the checks of the ABI's inputs, and the
// conversion to the ABI's disparity; the matching itself is sgm_engine.cpp.
#include "sgm_engine.hpp"
#include "sgm_kernels.hpp"

#include <binocle/plugin.hpp>
#include <binocle/settings.hpp>

#include <memory>
#include <new>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

namespace {

using binocle::sdk::Error;
using binocle::sdk::Param;

using binocle::sdk::sizeText;


class SgmMatcher : public binocle::sdk::Matcher {
public:
    static std::vector<binocle_param_desc> parameters() {
        return {
            Param::integer("min_disparity", "0").min(0).max(1024).unit("px")
                .help("smallest disparity searched"),
            Param::integer("num_disparities", "64").min(16).max(256).multipleOf(16).unit("px")
                .help("disparities min_disparity .. min_disparity + num_disparities - 1 are searched"),
            Param::integer("census_width_px", "9").min(3).max(11).odd().unit("px")
                .help("width of the census window; width x height - 1 <= 64 bits (9 x 7, 11 x 5, 7 x 9 ...)"),
            Param::integer("census_height_px", "7").min(3).max(9).odd().unit("px")
                .help("height of the census window"),
            Param::choice("census", "full", "full|centre_symmetric")
                .help("full: each neighbour against the centre (width x height - 1 bits); centre_symmetric: each pixel against its mirror image about the centre (half the bits, half the cost work)"),
            Param::choice("paths", "4", "4|5|8")
                .help("aggregation paths: 8 (all), 4 (horizontal and vertical) or 5 (left, right and the three from above: one pass, no volume, least memory)"),
            Param::integer("p1", "10").min(1).max(253)
                .help("penalty for a disparity change of 1 px between neighbours, in census bits (6 suits census: centre_symmetric)"),
            Param::integer("p2", "120").min(2).max(254)
                .help("penalty for a larger change, > p1; census bits + p2 <= 255 (8-bit path costs); 90 suits census: centre_symmetric"),
            Param::integer("p2_intensity_step", "30").min(0).max(255)
                .help("0 = p2 constant; else p2 * s / (s + |intensity step|), never below p1: cheaper jumps across edges"),
            Param::integer("uniqueness_ratio", "8").min(0).max(99).unit("%")
                .help("the best sum must beat every other (away from +-1 px) by this margin; 0 = no check"),
            Param::integer("disp12_max_diff", "1").min(-1).max(1024).unit("px")
                .help("largest difference allowed in the left-right consistency check; -1 = no check"),
            Param::boolean("subpixel", true)
                .help("refine each disparity by a parabola through the neighbouring sums (1/16 px)"),
            Param::integer("median_px", "5").min(1).max(5).odd().unit("px")
                .help("side of the median filter on the disparity; 1 = none"),
            Param::choice("fill", "none", "none|dense")
                .help("none: pixels no match survived for stay invalid; dense: each is filled (Hirschmueller 2008): an occlusion from the background side (second lowest of the nearest valid disparities along 8 directions), a mismatch from all sides (their median); the extra plane disparity_filled marks them"),
            Param::integer("stripes", "2").min(1).max(64)
                .help("horizontal stripes matched in parallel (each warms its paths up on 16 rows of the next); the result depends on it, not on the thread count"),
            Param::integer("max_memory_mb", "2048").min(16).max(1048576).unit("MiB")
                .help("refuse a pair whose working memory (with 4 or 8 paths: width x height x num_disparities x 2 bytes and more) would exceed this"),
            Param::choice("kernels", "auto", "auto|avx512|avx2|baseline|scalar")
                .help("instruction set: auto (the fastest this CPU runs), avx512 (512-bit vectors: AVX-512 F, BW, VL, DQ, CD, VBMI, VPOPCNTDQ and BITALG, as on Ice Lake and Zen 4 or later), avx2, baseline (SSE2 / NEON) or scalar (the reference)"),
        };
    }

    // `p` is checked by the SDK against the table above (defaults, ranges, odd sizes,
    // multiples and choices, refused in the words every plugin uses).
    SgmMatcher(const binocle::sdk::CheckedParams &p, binocle::sdk::Host &host) {
        sgm::Settings s;
        s.minDisparity = static_cast<int>(p.integer("min_disparity"));
        s.numDisparities = static_cast<int>(p.integer("num_disparities"));
        s.censusWidth = static_cast<int>(p.integer("census_width_px"));
        s.censusHeight = static_cast<int>(p.integer("census_height_px"));
        s.censusSymmetric = p.string("census") == "centre_symmetric";
        s.paths = std::stoi(p.string("paths"));
        s.p1 = static_cast<int>(p.integer("p1"));
        s.p2 = static_cast<int>(p.integer("p2"));
        s.p2IntensityStep = static_cast<int>(p.integer("p2_intensity_step"));
        s.uniquenessPercent = static_cast<int>(p.integer("uniqueness_ratio"));
        s.disp12MaxDiff = static_cast<int>(p.integer("disp12_max_diff"));
        s.subpixel = p.boolean("subpixel");
        s.medianPx = static_cast<int>(p.integer("median_px"));
        s.stripes = static_cast<int>(p.integer("stripes"));
        s.fillDense = p.string("fill") == "dense";
        s.maxMemoryBytes = static_cast<double>(p.integer("max_memory_mb")) * 1048576.0;
        // Rules across settings, in the same words.
        const int bits = sgm::censusBits(s.censusWidth, s.censusHeight, s.censusSymmetric);
        if (bits > 64)
            p.refuse("census_width_px x census_height_px", std::to_string(s.censusWidth) + " x " + std::to_string(s.censusHeight),
                     "a window of at most 64 census bits (width x height - 1: 9 x 7, 11 x 5, 7 x 9); this one has " +
                         std::to_string(bits));
        if (s.p2 <= s.p1) p.refuse("p2", std::to_string(s.p2), "more than p1 = " + std::to_string(s.p1));
        if (bits + s.p2 > 255)
            p.refuse("p2", std::to_string(s.p2),
                     "at most " + std::to_string(255 - bits) + " = 255 - the census window's " + std::to_string(bits) +
                         " bits (path costs are 8-bit)");
        const sgm::Kernels &kernels = kernelsOf(p);
        engine_ = std::make_unique<sgm::Engine>(s, kernels);
        minDisparity_ = s.minDisparity;
        numDisparities_ = s.numDisparities;
        host.debug("census " + std::to_string(s.censusWidth) + "x" + std::to_string(s.censusHeight) + ", paths " +
                   std::to_string(s.paths) + ", p1 " + std::to_string(s.p1) + ", p2 " + std::to_string(s.p2) +
                   ", kernels " + engine_->kernels().name);
    }

    void compute(const binocle_image &left, const binocle_image &right, binocle_image &disparity) override {
        binocle::sdk::checkMatcherImages(left, right, disparity, "sgm: ");
        try {
            cv::Mat out(disparity.height, disparity.width, CV_32FC1, disparity.data,
                        static_cast<size_t>(disparity.stride_bytes));
            engine_->compute(grey(left, greyLeft_), grey(right, greyRight_), out, BINOCLE_INVALID_DISPARITY);
        } catch (const std::invalid_argument &e) {
            throw Error(BINOCLE_ERR_INVALID_ARGUMENT, e.what());
        } catch (const std::bad_alloc &) {
            throw Error(BINOCLE_ERR_INTERNAL, "sgm: out of memory matching a " + sizeText(left) + " pair");
        } catch (const cv::Exception &e) {
            throw Error(BINOCLE_ERR_INTERNAL, "sgm: OpenCV failed on a " + sizeText(left) + " pair: " + e.err);
        }
    }

    std::pair<int32_t, int32_t> disparityRange() const override { return {minDisparity_, numDisparities_}; }

    // With fill: dense, the pixels filled in (255) rather than matched (0).
    std::vector<binocle_named_image> extras() override {
        const cv::Mat &filled = engine_->filled();
        if (filled.empty()) return {};
        const binocle_image plane{filled.cols, filled.rows, static_cast<int32_t>(filled.step[0]), BINOCLE_PIXEL_GRAY8,
                                  filled.data};
        return {{"disparity_filled", plane}};
    }

private:
    // The kernel table named by `kernels`, refused when this CPU or build lacks it.
    static const sgm::Kernels &kernelsOf(const binocle::sdk::CheckedParams &p) {
        const std::string &name = p.string("kernels");
        if (name == "scalar") return sgm::scalarKernels();
        if (name == "baseline") {
            if (const sgm::Kernels *k = sgm::baselineKernels()) return *k;
            p.refuse("kernels", "'baseline'", "auto or scalar (this build has no SIMD for this CPU's baseline)");
        }
        if (name == "avx2") {
            if (const sgm::Kernels *k = sgm::avx2Kernels()) return *k;
            p.refuse("kernels", "'avx2'", "auto, baseline or scalar (this CPU or this build has no AVX2)");
        }
        if (name == "avx512") {
            if (const sgm::Kernels *k = sgm::avx512Kernels()) return *k;
            p.refuse("kernels", "'avx512'",
                     "auto, avx2, baseline or scalar (this CPU or this build lacks one of AVX-512 F, BW, VL, DQ, CD, "
                     "VBMI, VPOPCNTDQ and BITALG)");
        }
        return sgm::bestKernels();
    }

    // 8-bit grey: a view of the pixels when already GRAY8, else converted into `buffer`.
    static cv::Mat grey(const binocle_image &im, cv::Mat &buffer) {
        if (im.format == BINOCLE_PIXEL_GRAY8)
            return cv::Mat(im.height, im.width, CV_8UC1, im.data, static_cast<size_t>(im.stride_bytes));
        const cv::Mat colour(im.height, im.width, CV_8UC3, im.data, static_cast<size_t>(im.stride_bytes));
        cv::cvtColor(colour, buffer, im.format == BINOCLE_PIXEL_RGB8 ? cv::COLOR_RGB2GRAY : cv::COLOR_BGR2GRAY);
        return buffer;
    }

    std::unique_ptr<sgm::Engine> engine_;
    cv::Mat greyLeft_, greyRight_;
    int minDisparity_ = 0, numDisparities_ = 0;
};

} // namespace

BINOCLE_EXPORT_MATCHER(SgmMatcher, "sgm", "1.0.0",
                       "census + semi-global matching (4, 5 or 8 paths), SIMD through OpenCV's universal intrinsics")

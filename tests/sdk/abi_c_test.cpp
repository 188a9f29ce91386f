// SPDX-License-Identifier: MIT
// The plugin ABI as C sees it: the same headers compiled as C11 and C99 (pedantic, warnings
// as errors) lay out every struct exactly as C++ does and as recorded in abi_layout.h.
#include "abi_layout.h"

#include <binocle/abi.h>

#include <gtest/gtest.h>

#include <cstddef>
#include <string>
#include <vector>

namespace {

struct Measure {
    std::string what;
    long long measured;
    long long recorded;
};

std::vector<Measure> cppLayout() {
    std::vector<Measure> out;
#define CPP_SIZE(type, bytes) out.push_back({"sizeof(" #type ")", static_cast<long long>(sizeof(type)), (bytes)});
#define CPP_FIELD(type, member, offset) \
    out.push_back({"offsetof(" #type ", " #member ")", static_cast<long long>(offsetof(type, member)), (offset)});
#define CPP_CONSTANT(name, value) out.push_back({#name, static_cast<long long>(name), (value)});
    BINOCLE_ABI_LAYOUT(CPP_SIZE, CPP_FIELD, CPP_CONSTANT)
#undef CPP_SIZE
#undef CPP_FIELD
#undef CPP_CONSTANT
    return out;
}

TEST(AbiC, CAndCppAgreeOnEveryLayout) {
    int count = 0;
    const binocle_test_layout_entry *c = binocle_test_c_layout(&count);
    const std::vector<Measure> cpp = cppLayout();
    ASSERT_EQ(static_cast<size_t>(count), cpp.size());
    ASSERT_GT(count, 100); // every struct, member and constant of the ABI is listed
    for (int i = 0; i < count; ++i) {
        EXPECT_EQ(c[i].what, cpp[i].what);
        EXPECT_EQ(c[i].measured, cpp[i].measured) << cpp[i].what << ": C and C++ disagree";
    }
}

TEST(AbiC, LayoutIsTheRecordedOne) {
    if (!BINOCLE_ABI_LAYOUT_RECORDED) GTEST_SKIP() << "layout recorded for 64-bit targets only";
    int count = 0;
    const binocle_test_layout_entry *c = binocle_test_c_layout(&count);
    for (int i = 0; i < count; ++i)
        EXPECT_EQ(c[i].measured, c[i].recorded)
            << c[i].what << " changed: an ABI break (bump BINOCLE_ABI_VERSION and record the new layout)";
}

TEST(AbiC, InvalidDisparityIsMinusOne) {
    EXPECT_EQ(BINOCLE_INVALID_DISPARITY, -1.0f);
    EXPECT_STREQ(BINOCLE_PLUGIN_INIT_SYMBOL, "binocle_plugin_init");
}

TEST(AbiC, C99TableWithDesignatedInitializers) {
    EXPECT_EQ(binocle_test_c99_version(), 199901L);
    const binocle_plugin_header *h = binocle_test_c99_table();
    ASSERT_NE(h, nullptr);
    EXPECT_EQ(h->struct_size, sizeof(binocle_matcher_api));
    EXPECT_EQ(h->abi_version, BINOCLE_ABI_VERSION);
    EXPECT_EQ(h->kind, BINOCLE_KIND_MATCHER);
    EXPECT_STREQ(h->name, "c99_table");
    auto t = reinterpret_cast<const binocle_matcher_api *>(h);
    ASSERT_EQ(t->param_count, 1);
    EXPECT_STREQ(t->params[0].name, "window_px");
    EXPECT_EQ(t->params[0].type, BINOCLE_PARAM_INT);
    EXPECT_EQ(t->params[0].min, 1.0);
    EXPECT_EQ(t->params[0].choices, nullptr); // members left out are zero
    EXPECT_NE(t->compute, nullptr);
    EXPECT_EQ(t->disparity_range, nullptr);
    binocle_matcher *m = reinterpret_cast<binocle_matcher *>(1);
    EXPECT_EQ(t->create(nullptr, 0, nullptr, &m), BINOCLE_ERR_UNSUPPORTED);
    EXPECT_EQ(m, nullptr);
    EXPECT_STREQ(t->last_error(nullptr), "c99 table: not a real matcher");
}

} // namespace

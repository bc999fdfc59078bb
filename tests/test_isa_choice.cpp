// The instruction set is chosen per buffer (BufferConfig::isa, common/isa_choice.hpp): a buffer
// keeps the one it was made with whatever select_isa does later, buffers on different
// instruction sets run side by side on different threads, and every one gives the scalar
// reference's bits. Nothing changes Highway's process-wide target.
#include "support.hpp"

#include <homcull/error.hpp>
#include <homcull/isa.hpp>
#include <homcull/occlusion_buffer.hpp>
#include <homcull/occlusion_maps.hpp>

#include "buffer/buffer_kernels.hpp"
#include "buffer/buffer_state.hpp"
#include "hom/map_kernels.hpp"
#include "hom/maps_state.hpp"

#include <hwy/targets.h>

#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <thread>
#include <vector>

namespace homcull {
namespace {

// Whether the buffer runs the kernel table of the instruction set `isa` (its bits alone cannot
// tell: every instruction set gives the same).
bool runs_kernels_of(const OcclusionBuffer& b, const std::string& isa) {
    return b.state().kernels_ == &detail::buffer_kernels(detail::isa_choice(isa));
}

BufferConfig config_on(const char* isa) {
    BufferConfig c = test::buffer_config(211, 97, 2, 1.0f);
    c.isa = isa;
    return c;
}

TEST(IsaChoice, EachBufferKeepsTheInstructionSetItWasMadeWith) {
    const std::vector<float> soup = test::random_clip_triangles(5, 4000, 0.3f);
    const TriangleInput in = test::clip_space_input(soup);
    OcclusionBuffer reference(config_on("scalar"));
    reference.render(in);
    EXPECT_STREQ(reference.config().isa, "scalar");
    EXPECT_EQ(reference.state().kernels_->raster.rows, &detail::rasterize_rows_reference);
    for (const std::string& isa : available_isas()) {
        OcclusionBuffer named(config_on(isa.c_str()));
        EXPECT_EQ(named.config().isa, isa);
        // select_isa changes the default of buffers made from now on, not this one's.
        const test::ScopedIsa other(isa == "scalar" ? "best" : "scalar");
        OcclusionBuffer by_default(config_on(nullptr));
        EXPECT_STREQ(by_default.config().isa, isa == "scalar" ? available_isas()[1].c_str() : "scalar");
        named.render(in);
        EXPECT_EQ(named.config().isa, isa);
        EXPECT_TRUE(runs_kernels_of(named, isa)) << isa;
        EXPECT_TRUE(runs_kernels_of(by_default, isa == "scalar" ? "best" : "scalar")) << isa;
        EXPECT_TRUE(test::same_subtiles(named, reference)) << isa;
        EXPECT_TRUE(test::same_pyramid(named, reference)) << isa;
        const std::vector<ScreenRect> rects = test::random_screen_rects(3, 500);
        EXPECT_TRUE(test::rect_answers(named, rects) == test::rect_answers(reference, rects)) << isa;
    }
}

// "best" names the best instruction set there is; a buffer made without a name takes
// select_isa's choice at that moment, and configure() takes it again.
TEST(IsaChoice, NullTakesTheProcessDefaultWhenMadeOrConfigured) {
    const std::vector<std::string> isas = available_isas();
    ASSERT_GE(isas.size(), 2u);  // scalar, then the best SIMD target
    EXPECT_STREQ(OcclusionBuffer(config_on("best")).config().isa, isas[1].c_str());
    OcclusionBuffer buffer(config_on(nullptr));
    EXPECT_EQ(buffer.config().isa, isas[1]);
    {
        const test::ScopedIsa scalar("scalar");
        EXPECT_EQ(selected_isa(), "scalar");
        EXPECT_EQ(buffer.config().isa, isas[1]);
        buffer.configure(config_on(nullptr));
        EXPECT_STREQ(buffer.config().isa, "scalar");
        EXPECT_TRUE(runs_kernels_of(buffer, "scalar"));
    }
    EXPECT_EQ(selected_isa(), isas[1]);
}

TEST(IsaChoice, UnknownOrUnavailableNamesAreRefused) {
    for (const char* name : {"avx9", "", "AVX2", "sve2_128_x"}) {
        const BufferConfig c = config_on(name);
        ASSERT_NE(buffer_config_problem(c), nullptr) << name;
        try {
            OcclusionBuffer b(c);
            ADD_FAILURE() << name << " was accepted";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("instruction set"), std::string::npos) << e.what();
        }
        EXPECT_THROW(select_isa(name), Error) << name;
    }
    EXPECT_EQ(selected_isa(), available_isas()[1]);  // a refused name leaves the selection alone
    // A configure that is refused leaves the buffer as it was, on its instruction set.
    OcclusionBuffer b(config_on("scalar"));
    EXPECT_THROW(b.configure(config_on("avx9")), Error);
    EXPECT_STREQ(b.config().isa, "scalar");
}

// Buffers on every instruction set render and answer at once, each on its own thread, and give
// the bits each gives alone (no instruction set leaks from one thread's buffer to another's).
TEST(IsaChoice, BuffersOnDifferentInstructionSetsRunSideBySide) {
    const std::vector<float> soup = test::random_clip_triangles(9, 6000, 0.25f);
    const TriangleInput in = test::clip_space_input(soup);
    OcclusionBuffer alone(config_on("scalar"));
    alone.render(in);
    const std::vector<std::string> isas = available_isas();
    std::vector<OcclusionBuffer> buffers;
    for (const std::string& isa : isas) buffers.emplace_back(config_on(isa.c_str()));
    std::vector<std::thread> threads;
    for (OcclusionBuffer& b : buffers)
        threads.emplace_back([&b, &in] {
            for (int round = 0; round < 3; ++round) {
                b.clear();
                b.render(in);
            }
        });
    for (std::thread& t : threads) t.join();
    for (std::size_t k = 0; k < isas.size(); ++k) {
        EXPECT_TRUE(runs_kernels_of(buffers[k], isas[k]));
        EXPECT_TRUE(test::same_subtiles(buffers[k], alone)) << isas[k];
        EXPECT_TRUE(test::same_pyramid(buffers[k], alone)) << isas[k];
    }
}

// Occlusion maps run the instruction set of the buffer they are built from.
TEST(IsaChoice, MapsFollowTheirBuffer) {
    const std::vector<float> soup = test::random_clip_triangles(13, 3000, 0.3f);
    const TriangleInput in = test::clip_space_input(soup);
    OcclusionMapsConfig maps_config;
    maps_config.display_width = 211 * 2;
    maps_config.display_height = 97 * 2;
    OcclusionBuffer reference_buffer(config_on("scalar"));
    reference_buffer.render(in);
    OcclusionMaps reference(reference_buffer, maps_config);
    reference.build(reference_buffer);
    EXPECT_EQ(reference.state().built_with_->level0, nullptr);  // the scalar reference's
    const test::ScopedIsa scalar_default("scalar");  // what the maps must not follow
    for (const std::string& isa : available_isas()) {
        OcclusionBuffer buffer(config_on(isa.c_str()));
        buffer.render(in);
        OcclusionMaps maps(buffer, maps_config);
        maps.build(buffer);
        EXPECT_EQ(maps.state().built_with_, &detail::map_kernels(detail::isa_choice(isa))) << isa;
        std::size_t differing = 0;
        for (const ScreenRect& r : test::random_screen_rects(17, 500))
            differing += maps.test_rect(r).visibility != reference.test_rect(r).visibility;
        EXPECT_EQ(differing, 0u) << isa;
    }
}

// select_isa leaves Highway's own choice (HWY_DYNAMIC_DISPATCH's) alone: it used to force it
// with hwy::SetSupportedTargetsForTest, for every user of Highway in the process.
TEST(IsaChoice, SelectionLeavesHighwaysProcessWideTargetsAlone) {
    const std::int64_t before = hwy::SupportedTargets();
    for (const std::string& isa : available_isas()) {
        const test::ScopedIsa selected(isa);
        EXPECT_EQ(hwy::SupportedTargets(), before) << isa;
    }
}

}  // namespace
}  // namespace homcull

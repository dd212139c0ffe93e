// The resource view (render/passes/view): a frame resource shown in place of the composite. The
// view of the G-buffer's albedo is the albedo the renderer reads back, pixel for pixel (the
// must-fail: the composite is not); the knob round-trips NAME*SCALE; a resource no pass makes,
// the composite itself and a buffer are clear errors naming the knob; off, the frame is unchanged.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "core/Error.h"
#include "core/gl/Context.h"
#include "render/PassKnob.h"
#include "render/Renderer.h"
#include "render/passes/gbuffer/GBufferPass.h"
#include "render/passes/view/ViewOptions.h"
#include "tests/support/TestSupport.h"
#include "testscenes/TurnedBoxScene.h"

namespace mirage::render {
namespace {

RendererOptions withView(const std::string& value) {
    RendererOptions o;
    findPassKnob("view")->apply(o, value);
    return o;
}

TEST(ResourceView, ShowsTheResourceInPlaceOfTheComposite) {
    gl::Context context = gl::Context::headless();
    const test::TurnedBoxScene s = test::makeTurnedBoxScene();
    Renderer plain(s.scene, s.cam, RendererOptions{});
    plain.render({s.pose, cv::Mat(), true});
    const cv::Mat albedo = plain.readBuffer(kGBufferAlbedo);
    ASSERT_EQ(albedo.size(), plain.compositeLinear().size()) << "the test wants canvas = camera";

    Renderer viewed(s.scene, s.cam, withView("GBufferAlbedo"));
    viewed.render({s.pose, cv::Mat(), true});
    // Albedos are 0.04 (the box) and 0.7 (the table); the view reads them nearest, unscaled.
    EXPECT_LT(test::meanAbsDiff(viewed.compositeLinear(), albedo), 1e-3);
    EXPECT_GT(test::meanAbsDiff(plain.compositeLinear(), albedo), 0.05)
        << "must-fail: not the view";

    Renderer scaled(s.scene, s.cam, withView("GBufferAlbedo*0.5"));
    scaled.render({s.pose, cv::Mat(), true});
    EXPECT_LT(test::meanAbsDiff(scaled.compositeLinear(), albedo * 0.5), 1e-3);
}

TEST(ResourceView, OffLeavesTheFrameAsRendered) {
    gl::Context context = gl::Context::headless();
    const test::TurnedBoxScene s = test::makeTurnedBoxScene();
    Renderer plain(s.scene, s.cam, RendererOptions{});
    plain.render({s.pose, cv::Mat(), true});
    Renderer off(s.scene, s.cam, withView("off"));
    off.render({s.pose, cv::Mat(), true});
    EXPECT_LT(test::meanAbsDiff(off.compositeLinear(), plain.compositeLinear()), 1e-6);
}

TEST(ResourceView, TheKnobReadsBackAndRefusesBadValues) {
    const PassKnob* k = findPassKnob("view");
    ASSERT_NE(k, nullptr);
    EXPECT_EQ(k->read(RendererOptions{}), "off");
    EXPECT_EQ(k->read(withView("LRv*4")), "LRv*4");
    EXPECT_EQ(withView("LRv*4").passes.get<ViewOptions>().scale, 4.0f);
    RendererOptions o;
    for (const char* bad : {"*2", "LRv*0", "LRv*x", "LRv*-1", "bogus", "LR v"}) {
        try {
            k->apply(o, bad);
            ADD_FAILURE() << bad << " was accepted";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("knob 'view'"), std::string::npos) << e.what();
        }
    }
}

TEST(ResourceView, ResourcesItCannotShowAreErrorsNamingTheKnob) {
    gl::Context context = gl::Context::headless();
    const test::TurnedBoxScene s = test::makeTurnedBoxScene();
    for (const char* name : {"NoSuchBuffer", "Composite"}) {
        try {
            Renderer r(s.scene, s.cam, withView(name));
            ADD_FAILURE() << name << " was accepted";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("knob 'view'"), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
        }
    }
    // Vpls is a storage buffer: refused when the frame would show it.
    Renderer r(s.scene, s.cam, withView("Vpls"));
    EXPECT_THROW(r.render({s.pose, cv::Mat(), true}), Error);
}

}  // namespace
}  // namespace mirage::render

#include "render/passes/view/ResourceViewPass.h"

#include <fmt/format.h>

#include "core/Error.h"
#include "render/FrameGraph.h"
#include "render/PassRegistry.h"
#include "render/passes/composite/CompositePass.h"

namespace mirage::render {
namespace {
#include "render/passes/view/view_units.glsl"

bool isIntegerFormat(GLenum f) {
    switch (f) {
        case GL_R8UI:
        case GL_R16UI:
        case GL_R32UI:
        case GL_RG8UI:
        case GL_RG16UI:
        case GL_RG32UI:
        case GL_RGBA8UI:
        case GL_RGBA16UI:
        case GL_RGBA32UI:
        case GL_R8I:
        case GL_R16I:
        case GL_R32I:
        case GL_RG8I:
        case GL_RG16I:
        case GL_RG32I:
        case GL_RGBA8I:
        case GL_RGBA16I:
        case GL_RGBA32I:
            return true;
        default:
            return false;
    }
}

bool isSingleChannel(GLenum f) {
    switch (f) {
        case GL_R8:
        case GL_R16:
        case GL_R16F:
        case GL_R32F:
        case GL_DEPTH_COMPONENT16:
        case GL_DEPTH_COMPONENT24:
        case GL_DEPTH_COMPONENT32:
        case GL_DEPTH_COMPONENT32F:
            return true;
        default:
            return false;
    }
}

}  // namespace

ResourceViewPass::ResourceViewPass(const ViewOptions& options)
    : options_(options),
      resourceName_(options.resource),
      nearest_("view nearest", GL_NEAREST, GL_NEAREST, GL_CLAMP_TO_EDGE) {
    options_.validate();
    if (resourceName_.empty()) return;  // off: nothing to compile
    flatProgram_ = fullscreenProgram("view", "passes/view/view.frag");
    arrayProgram_ = fullscreenProgram("view (array layer)", "passes/view/view.frag",
                                      "#define MIRAGE_VIEW_ARRAY\n");
}

void ResourceViewPass::setup(PassBuilder& b) const {
    CompositeVersion::declare(b);
    if (resourceName_.empty()) return;
    const Resource shown{resourceName_.c_str()};
    if (shown == kComposite || shown == kCompositeSrgb)
        throw Error(
            fmt::format("knob 'view': '{}' is the frame's output already; name another "
                        "resource (GBufferNormal, LRv, ...) or 'off'",
                        resourceName_));
    if (!b.declared(shown))
        throw Error(
            fmt::format("knob 'view': no pass of this frame makes a resource '{}' (names "
                        "are case-sensitive; docs/realtime-renderer.md lists each pass's)",
                        resourceName_));
    b.read(shown);
}

PassDecision ResourceViewPass::decide(const FrameContext&) const {
    if (resourceName_.empty()) return {false, "no resource to view"};
    return {true, fmt::format("showing {} (x{})", resourceName_, options_.scale)};
}

void ResourceViewPass::resize(const FrameContext& ctx) {
    output_.resize(ctx.projection.camera.width, ctx.projection.camera.height);
}

void ResourceViewPass::execute(FrameContext& ctx, PassResources& res) {
    const Resource shown{resourceName_.c_str()};
    if (!res.hasTexture(shown))
        throw Error(
            fmt::format("knob 'view': '{}' is a buffer, not a texture: the view shows "
                        "textures",
                        resourceName_));
    const gl::Texture& t = res.texture(shown);
    GLint target = 0;
    glGetTextureParameteriv(t.id(), GL_TEXTURE_TARGET, &target);
    if (isIntegerFormat(t.format()) || (target != GL_TEXTURE_2D && target != GL_TEXTURE_2D_ARRAY))
        throw Error(
            fmt::format("knob 'view': '{}' is {}; the view shows float and normalised 2D "
                        "textures and the first layer of 2D arrays",
                        resourceName_,
                        isIntegerFormat(t.format()) ? "an integer texture"
                                                    : "neither a 2D texture nor an array"));
    const gl::Program& program = target == GL_TEXTURE_2D_ARRAY ? arrayProgram_ : flatProgram_;
    output_.bind();
    glEnable(GL_FRAMEBUFFER_SRGB);
    ctx.beginFullscreen(program, ctx.projection.camera.width, ctx.projection.camera.height);
    glUniform1f(program.uniformLocation("scale"), options_.scale);
    glUniform1i(program.uniformLocation("layer"), 0);
    glUniform1i(program.uniformLocation("singleChannel"), isSingleChannel(t.format()) ? 1 : 0);
    glBindTextureUnit(kUnitViewSource, t.id());
    glBindSampler(kUnitViewSource, nearest_.id());
    ctx.drawFullscreenTriangle();
    glBindSampler(kUnitViewSource, 0);
    glDisable(GL_FRAMEBUFFER_SRGB);
    output_.publish(res);
}

// Registered in render/PassList.cpp.
std::unique_ptr<RenderPass> makeResourceViewPass(const PassInit& init) {
    return std::make_unique<ResourceViewPass>(init.options.passes.get<ViewOptions>());
}

}  // namespace mirage::render

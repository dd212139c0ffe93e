#include "render/passes/exposure/ExposurePass.h"

#include <algorithm>
#include <cstddef>
#include <optional>

#include <fmt/format.h>

#include "core/Error.h"
#include "render/FrameGraph.h"
#include "render/FrameImports.h"
#include "render/PassOptions.h"
#include "render/PassRegistry.h"
#include "render/RadiometricRatio.h"
#include "render/passes/caustic/CausticPass.h"
#include "render/passes/direct/DirectLightPass.h"
#include "render/passes/gbuffer/GBufferPass.h"
#include "render/passes/grain/CameraGrain.h"

namespace mirage::render {
namespace {
constexpr int kMaxTaps = 4;  // per side of a block: 16 taps bound the pass's cost
}  // namespace

void ExposureMatchOptions::validate() const {
    checkOption(sampleColumns >= 4 && sampleColumns <= 1024, "exposureMatch.sampleColumns",
                "4..1024", sampleColumns);
    checkOption(maxBlockVariation >= 1.0f && maxBlockVariation <= 100.0f,
                "exposureMatch.maxBlockVariation", "in [1, 100]", maxBlockVariation);
    checkOption(maxBlockNoise > 0.0f && maxBlockNoise <= 1.0f, "exposureMatch.maxBlockNoise",
                "in (0, 1]", maxBlockNoise);
    tracker.validate();
}

ExposurePass::ExposurePass()
    : program_(fullscreenProgram("exposure samples", "passes/exposure/exposure_samples.frag")) {}

ExposurePass::Grid ExposurePass::grid(int canvasWidth, int canvasHeight, int sampleColumns) {
    Grid g;
    g.block = std::max(1, (canvasWidth + sampleColumns - 1) / sampleColumns);
    g.columns = std::max(1, canvasWidth / g.block);
    g.rows = std::max(1, canvasHeight / g.block);
    g.taps = std::min(g.block, kMaxTaps);
    g.stride = std::max(1, g.block / g.taps);
    return g;
}

void ExposurePass::setup(PassBuilder& b) const {
    b.read(kCameraImage);
    b.read(kLR);
    b.read(kGBufferPosition);
    b.read(kGBufferEmissive);
    b.readOptional(kCausticR);
    b.create(kExposureSamples, {GL_RGBA32F, SizeRule::Scene, Storage::PassOwned});
}

PassDecision ExposurePass::decide(const FrameContext& ctx) const {
    if (!ctx.options.exposureMatch.enabled)
        return {false, "exposure matching off: the fixed exposure applies"};
    return {true, fmt::format("footage / L_r in {}x{} blocks", grid_.columns, grid_.rows)};
}

void ExposurePass::resize(const FrameContext& ctx) {
    if (!trackerConfigured_) {
        // The options are the renderer's for its whole life: the prior and settings once.
        tracker_ = ExposureTracker(glm::dvec3(double(ctx.options.composite.exposure)),
                                   ctx.options.exposureMatch.tracker);
        trackerConfigured_ = true;
    }
    const int cw = ctx.canvasWidth(), ch = ctx.canvasHeight();
    if (cw == canvasW_ && ch == canvasH_) return;
    canvasW_ = cw;
    canvasH_ = ch;
    grid_ = grid(cw, ch, ctx.options.exposureMatch.sampleColumns);
    footage_ = gl::Texture::create2D("exposure footage", grid_.columns, grid_.rows, GL_RGBA32F);
    rendered_ = gl::Texture::create2D("exposure L_r", grid_.columns, grid_.rows, GL_RGBA32F);
    fbo_ = gl::Framebuffer("exposure fbo");
    fbo_.attachColor(0, footage_);
    fbo_.attachColor(1, rendered_);
    fbo_.finalize(2);
    const std::vector<glm::vec2> table = ctx.projection.canvasToCameraTable();
    canvasToCamera_ = gl::Texture::create2D("exposure canvas to camera", cw, ch, GL_RG32F);
    canvasToCamera_.setFilter(GL_NEAREST, GL_NEAREST);
    canvasToCamera_.upload(GL_RG, GL_FLOAT, table.data());
    blockR2_ = blockRadii2(grid_, cw, ch, table, ctx.projection.camera);
    footageRead_.assign(size_t(grid_.columns) * size_t(grid_.rows) * 4, 0.0f);
    renderedRead_.assign(footageRead_.size(), 0.0f);
}

std::vector<float> ExposurePass::blockRadii2(const Grid& grid, int cw, int ch,
                                             const std::vector<glm::vec2>& table,
                                             const CameraIntrinsics& camera) {
    std::vector<float> r2(size_t(grid.columns) * size_t(grid.rows), -1.0f);
    for (int by = 0; by < grid.rows; ++by)
        for (int bx = 0; bx < grid.columns; ++bx) {
            const int x = std::min(cw - 1, bx * grid.block + grid.block / 2);
            const int y = std::min(ch - 1, by * grid.block + grid.block / 2);
            const glm::vec2 q = table[size_t(y) * size_t(cw) + size_t(x)];
            if (q.x > -1000.0f)
                r2[size_t(by) * size_t(grid.columns) + size_t(bx)] = vignetteRadius2(camera, q);
        }
    return r2;
}

void ExposurePass::execute(FrameContext& ctx, PassResources& res) {
    const ExposureMatchOptions& o = ctx.options.exposureMatch;
    fbo_.bind();
    ctx.beginFullscreen(program_, grid_.columns, grid_.rows);
    glUniform1i(program_.uniformLocation("blockSize"), grid_.block);
    glUniform1i(program_.uniformLocation("taps"), grid_.taps);
    glUniform1i(program_.uniformLocation("stride"), grid_.stride);
    glUniform1i(program_.uniformLocation("withCaustics"), res.has(kCausticR) ? 1 : 0);
    glUniform1f(program_.uniformLocation("maxVariation"), o.maxBlockVariation);
    glBindTextureUnit(kUnitExposureCamera, res.texture(kCameraImage).id());
    glBindTextureUnit(kUnitExposureLR, res.texture(kLR).id());
    glBindTextureUnit(kUnitExposureCausticR, res.textureOr(kCausticR, ctx.blackTexture()).id());
    glBindTextureUnit(kUnitExposurePosition, res.texture(kGBufferPosition).id());
    glBindTextureUnit(kUnitExposureEmissive, res.texture(kGBufferEmissive).id());
    glBindTextureUnit(kUnitExposureCanvasToCamera, canvasToCamera_.id());
    ctx.drawFullscreenTriangle();

    // The readback waits for the frame so far (on llvmpipe: for its rasterisation); the blocks
    // are small (80 x 60 x 2 RGBA32F at 640x480: 77 KB).
    const GLsizei bytes = GLsizei(footageRead_.size() * sizeof(float));
    glGetTextureImage(footage_.id(), 0, GL_RGBA, GL_FLOAT, bytes, footageRead_.data());
    glGetTextureImage(rendered_.id(), 0, GL_RGBA, GL_FLOAT, bytes, renderedRead_.data());
    RadiometricRatio ratios;
    int real = 0, badlyExposed = 0, noisy = 0;
    // With the vignetting matched, the gain is the one at the principal point (the grain pass
    // darkens the virtual pixels towards the corners): each block's footage over V there.
    const VignetteMatchOptions& vo = ctx.options.grain.vignette;
    const bool devignette = vo.enabled && (vo.profile || ctx.vignette);
    const VignetteProfile vignette = !devignette  ? VignetteProfile{}
                                     : vo.profile ? *vo.profile
                                                  : *ctx.vignette;
    for (size_t i = 0; i + 3 < footageRead_.size(); i += 4) {
        if (footageRead_[i + 3] < 0.5f) continue;
        ++real;
        const glm::dvec3 measured(footageRead_[i], footageRead_[i + 1], footageRead_[i + 2]);
        const glm::dvec3 expected(renderedRead_[i], renderedRead_[i + 1], renderedRead_[i + 2]);
        if (!wellExposedLinear(measured)) {
            ++badlyExposed;
            continue;
        }
        if (!(renderedRead_[i + 3] <= o.maxBlockNoise)) {
            ++noisy;
            continue;
        }
        const float r2 = blockR2_[i / 4];
        const double v = devignette && r2 >= 0.0f ? double(vignette.gain(r2)) : 1.0;
        ratios.add(measured / std::max(v, 1e-3), expected);
    }
    const std::string why = fmt::format(
        "{} of {} sample blocks show unhidden real surfaces, smooth in the model and unclipped "
        "in the footage; {} of those are too dark or too bright, {} too noisy: {} usable, {} "
        "needed",
        real, grid_.columns * grid_.rows, badlyExposed, noisy, ratios.size(), o.tracker.minSamples);
    ctx.exposure = tracker_.update(ratios, why, ctx.reportedExposure);
    ctx.frame.exposure = glm::vec3(ctx.exposure.gain);
    // Only the gain changes: the passes after this one read it from the frame block.
    ctx.frameUbo.upload(&ctx.frame.exposure, sizeof(ctx.frame.exposure),
                        offsetof(GpuFrame, exposure));
    res.publish(kExposureSamples, footage_);
}

// Registered in render/PassList.cpp.
std::unique_ptr<RenderPass> makeExposurePass(const PassInit&) {
    return std::make_unique<ExposurePass>();
}

}  // namespace mirage::render

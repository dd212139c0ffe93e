#include "render/passes/grain/GrainPass.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

#include <fmt/format.h>

#include "render/FrameGraph.h"
#include "render/FrameImports.h"
#include "render/PassOptions.h"
#include "render/PassRegistry.h"
#include "render/passes/caustic/CausticPass.h"
#include "render/passes/composite/CompositePass.h"
#include "render/passes/composite/CompositeVersion.h"
#include "render/passes/direct/DirectLightPass.h"
#include "render/passes/gbuffer/GBufferPass.h"

namespace mirage::render {
namespace {

uint32_t mixSeed(uint32_t seed, int frame) {
    uint32_t h = seed * 0x9E3779B9u ^ uint32_t(frame) * 0x85EBCA6Bu;
    h ^= h >> 16;
    h *= 0x7FEB352Du;
    h ^= h >> 15;
    return h;
}

}  // namespace

void GrainOptions::validate() const {
    checkOption(sampleColumns >= 4 && sampleColumns <= 1024, "grain.sampleColumns", "4..1024",
                sampleColumns);
    checkOption(maxBlockVariation >= 1.0f && maxBlockVariation <= 100.0f, "grain.maxBlockVariation",
                "in [1, 100]", maxBlockVariation);
    checkOption(history >= 0.0f && history <= 0.99f, "grain.history", "in [0, 0.99]", history);
    checkOption(noise.minBlocksPerLevel >= 1 && noise.minBlocksPerLevel <= 100000,
                "grain.noise.minBlocksPerLevel", "1..100000", noise.minBlocksPerLevel);
    checkOption(vignette.minBlocks >= 3 && vignette.minBlocks <= 1000000,
                "grain.vignette.minBlocks", "3..1000000", vignette.minBlocks);
    checkOption(vignette.frames >= 2 && vignette.frames <= 64, "grain.vignette.frames", "2..64",
                vignette.frames);
    checkOption(vignette.refitInterval >= 1 && vignette.refitInterval <= 64,
                "grain.vignette.refitInterval", "1..64", vignette.refitInterval);
    checkOption(vignette.cellSize > 0.0f && vignette.cellSize <= 1.0f, "grain.vignette.cellSize",
                "in (0, 1] m", vignette.cellSize);
    checkOption(vignette.minSpread >= 0.0f && vignette.minSpread <= 1.0f,
                "grain.vignette.minSpread", "in [0, 1]", vignette.minSpread);
    if (vignette.profile) {
        const VignetteProfile& p = *vignette.profile;
        const float corner = p.gain(1.0f), mid = p.gain(0.25f);
        checkOption(std::isfinite(p.k1) && std::isfinite(p.k2) && corner > 0.0f && mid > 0.0f,
                    "grain.vignette.profile (k1, k2)",
                    "a profile 1 + k1 r^2 + k2 r^4 positive on [0, 1]", double(corner));
    }
}

GrainPass::GrainPass()
    : samplesProgram_(fullscreenProgram("grain samples", "passes/grain/grain_samples.frag")),
      applyProgram_(fullscreenProgram("grain apply", "passes/grain/grain_apply.frag")) {}

void GrainPass::setup(PassBuilder& b) const {
    b.read(kCameraImage);
    b.read(kLR);
    b.read(kGBufferPosition);
    b.read(kGBufferEmissive);
    b.read(kCompositeFootage);  // what of a virtual pixel is video: not vignetted twice
    b.readOptional(kCausticR);
    CompositeVersion::declare(b);
}

PassDecision GrainPass::decide(const FrameContext& ctx) const {
    const GrainOptions& o = ctx.options.grain;
    if (!o.noise.enabled && !o.vignette.enabled)
        return {false, "noise and vignetting matching off: the renderer's pixels stay clean"};
    return {true, fmt::format("noise {}; vignetting {}",
                              o.noise.enabled ? ctx.grainEstimates.noiseNote : "off",
                              o.vignette.enabled ? ctx.vignetteNote : "off")};
}

void GrainPass::resize(const FrameContext& ctx) {
    const CameraProjection& p = ctx.projection;
    const int cw = ctx.canvasWidth(), ch = ctx.canvasHeight();
    output_.resize(p.camera.width, p.camera.height);
    if (cw == canvasW_ && ch == canvasH_) return;
    canvasW_ = cw;
    canvasH_ = ch;
    grid_ = ExposurePass::grid(cw, ch, ctx.options.grain.sampleColumns);
    footage_ = gl::Texture::create2D("grain footage", grid_.columns, grid_.rows, GL_RGBA32F);
    rendered_ = gl::Texture::create2D("grain L_r", grid_.columns, grid_.rows, GL_RGBA32F);
    noise_ = gl::Texture::create2D("grain noise", grid_.columns, grid_.rows, GL_RGBA32F);
    position_ = gl::Texture::create2D("grain position", grid_.columns, grid_.rows, GL_RGBA32F);
    samplesFbo_ = gl::Framebuffer("grain samples fbo");
    samplesFbo_.attachColor(0, footage_);
    samplesFbo_.attachColor(1, rendered_);
    samplesFbo_.attachColor(2, noise_);
    samplesFbo_.attachColor(3, position_);
    samplesFbo_.finalize(4);
    const std::vector<glm::vec2> table = p.canvasToCameraTable();
    canvasToCamera_ = gl::Texture::create2D("grain canvas to camera", cw, ch, GL_RG32F);
    canvasToCamera_.setFilter(GL_NEAREST, GL_NEAREST);
    canvasToCamera_.upload(GL_RG, GL_FLOAT, table.data());
    // Each block's centre in the camera image (canvas rows are GL rows: row 0 at the bottom of
    // the canvas texture is the table's row 0, as the shaders read it).
    blockR2_ = ExposurePass::blockRadii2(grid_, cw, ch, table, p.camera);
    footageRead_.assign(size_t(grid_.columns) * size_t(grid_.rows) * 4, 0.0f);
    renderedRead_.assign(footageRead_.size(), 0.0f);
    noiseRead_.assign(footageRead_.size(), 0.0f);
    positionRead_.assign(footageRead_.size(), 0.0f);
}

void GrainPass::sampleBlocks(FrameContext& ctx, PassResources& res) {
    samplesFbo_.bind();
    ctx.beginFullscreen(samplesProgram_, grid_.columns, grid_.rows);
    glUniform1i(samplesProgram_.uniformLocation("blockSize"), grid_.block);
    glUniform1i(samplesProgram_.uniformLocation("taps"), grid_.taps);
    glUniform1i(samplesProgram_.uniformLocation("stride"), grid_.stride);
    glUniform1i(samplesProgram_.uniformLocation("withCaustics"), res.has(kCausticR) ? 1 : 0);
    glUniform1f(samplesProgram_.uniformLocation("maxVariation"),
                ctx.options.grain.maxBlockVariation);
    glBindTextureUnit(kUnitGrainCamera, res.texture(kCameraImage).id());
    glBindTextureUnit(kUnitGrainLR, res.texture(kLR).id());
    glBindTextureUnit(kUnitGrainCausticR, res.textureOr(kCausticR, ctx.blackTexture()).id());
    glBindTextureUnit(kUnitGrainPosition, res.texture(kGBufferPosition).id());
    glBindTextureUnit(kUnitGrainEmissive, res.texture(kGBufferEmissive).id());
    glBindTextureUnit(kUnitGrainCanvasToCamera, canvasToCamera_.id());
    ctx.drawFullscreenTriangle();
    const GLsizei bytes = GLsizei(footageRead_.size() * sizeof(float));
    glGetTextureImage(footage_.id(), 0, GL_RGBA, GL_FLOAT, bytes, footageRead_.data());
    glGetTextureImage(rendered_.id(), 0, GL_RGBA, GL_FLOAT, bytes, renderedRead_.data());
    glGetTextureImage(noise_.id(), 0, GL_RGBA, GL_FLOAT, bytes, noiseRead_.data());
    glGetTextureImage(position_.id(), 0, GL_RGBA, GL_FLOAT, bytes, positionRead_.data());
}

void GrainPass::estimate(FrameContext& ctx) {
    const GrainOptions& o = ctx.options.grain;
    std::vector<NoiseBlock> blocks;
    std::vector<VignetteSample> samples;
    auto lum = [](const float* c) { return 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2]; };
    for (size_t b = 0; b < blockR2_.size(); ++b) {
        const float* f = &footageRead_[b * 4];
        const float* r = &renderedRead_[b * 4];
        const float* n = &noiseRead_[b * 4];
        const float* p = &positionRead_[b * 4];
        if (f[3] < 0.5f) continue;
        blocks.push_back({{f[0], f[1], f[2]}, {n[0], n[1], n[2]}, n[3]});
        const float lr = lum(r);
        if (blockR2_[b] >= 0.0f && lr > 0.0f)
            samples.push_back({blockR2_[b], lum(f) / lr, {p[0], p[1], p[2]}});
    }
    if (o.noise.enabled) {
        std::string why;
        const auto nlf = estimateNoiseLevels(blocks, o.noise.minBlocksPerLevel, why);
        ctx.grainEstimates.updateNoise(nlf, o.history, why);
    }
    if (o.vignette.enabled && !o.vignette.profile) {
        std::string why;
        ctx.grainEstimates.addVignetteSamples(std::move(samples), size_t(o.vignette.frames));
        if (!ctx.grainEstimates.vignette() || ctx.frameIndex % o.vignette.refitInterval == 0) {
            const auto v =
                fitVignetteAcrossFrames(ctx.grainEstimates.vignetteSamples(), o.vignette.cellSize,
                                        o.vignette.minBlocks, o.vignette.minSpread, why);
            ctx.grainEstimates.updateVignette(v, o.history, why);
        }
    }
}

void GrainPass::apply(FrameContext& ctx, PassResources& res) {
    const GrainOptions& o = ctx.options.grain;
    const CameraIntrinsics& cam = ctx.projection.camera;
    output_.bind();
    glEnable(GL_FRAMEBUFFER_SRGB);
    ctx.beginFullscreen(applyProgram_, cam.width, cam.height);
    const bool noise = o.noise.enabled && ctx.grainEstimates.noise().has_value();
    const bool vignetteOn = o.vignette.enabled && ctx.vignette.has_value();
    const VignetteProfile vignette = vignetteOn ? *ctx.vignette : VignetteProfile{};
    glUniform1i(applyProgram_.uniformLocation("noiseOn"), noise ? 1 : 0);
    glUniform1i(applyProgram_.uniformLocation("vignetteOn"), vignetteOn ? 1 : 0);
    if (noise) {
        const NoiseLevelFunction& f = *ctx.grainEstimates.noise();
        glUniform3fv(applyProgram_.uniformLocation("noiseVariance"), kNoiseLevels,
                     &f.variance[0].x);
        // Correlated noise n = (w + beta (sum of the 4 neighbours' w)) / sqrt(1 + 4 beta^2) has
        // neighbour correlation 2 beta / (1 + 4 beta^2): beta from the measured correlation.
        const float rho = std::clamp(f.correlation, 0.0f, 0.45f);
        const float beta =
            rho > 1e-4f ? (1.0f - std::sqrt(1.0f - 4.0f * rho * rho)) / (4.0f * rho) : 0.0f;
        glUniform1f(applyProgram_.uniformLocation("beta"), beta);
        glUniform1ui(applyProgram_.uniformLocation("seed"), mixSeed(o.noise.seed, ctx.frameIndex));
        glUniform1i(applyProgram_.uniformLocation("footageGrain"), o.noise.footageGrain ? 1 : 0);
    }
    if (vignetteOn) {
        glUniform2f(applyProgram_.uniformLocation("vignetteK"), vignette.k1, vignette.k2);
        const double w = cam.width - 1, h = cam.height - 1;
        const double dx = std::max(cam.cx, w - cam.cx), dy = std::max(cam.cy, h - cam.cy);
        glUniform2f(applyProgram_.uniformLocation("principalPoint"), float(cam.cx), float(cam.cy));
        glUniform1f(applyProgram_.uniformLocation("invCornerR2"),
                    float(1.0 / std::max(dx * dx + dy * dy, 1.0)));
    }
    glBindTextureUnit(kUnitGrainComposite, res.texture(kComposite).id());
    glBindTextureUnit(kUnitGrainFootageShare, res.texture(kCompositeFootage).id());
    glBindTextureUnit(kUnitGrainCamera, res.texture(kCameraImage).id());
    ctx.drawFullscreenTriangle();
    glDisable(GL_FRAMEBUFFER_SRGB);
    output_.publish(res);
}

void GrainPass::execute(FrameContext& ctx, PassResources& res) {
    const GrainOptions& o = ctx.options.grain;
    if (o.noise.enabled || (o.vignette.enabled && !o.vignette.profile)) {
        sampleBlocks(ctx, res);
        estimate(ctx);
    }
    if (o.vignette.enabled) {
        if (o.vignette.profile) {
            ctx.vignette = o.vignette.profile;
            ctx.vignetteNote = fmt::format("given (k1 {:.3f}, k2 {:.3f})", o.vignette.profile->k1,
                                           o.vignette.profile->k2);
        } else {
            ctx.vignette = ctx.grainEstimates.vignette();
            ctx.vignetteNote = ctx.grainEstimates.vignetteNote;
        }
    }
    apply(ctx, res);
}

// Registered in render/PassList.cpp.
std::unique_ptr<RenderPass> makeGrainPass(const PassInit&) {
    return std::make_unique<GrainPass>();
}

}  // namespace mirage::render

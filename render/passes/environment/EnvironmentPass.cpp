#include "render/passes/environment/EnvironmentPass.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <glm/gtc/type_ptr.hpp>

#include "core/Error.h"
#include "render/FrameGraph.h"
#include "render/FrameImports.h"
#include "render/PassRegistry.h"

namespace mirage::render {
namespace {

// The SH9 projection reads the first mip level at most this wide: SH9 is very low frequency
// (the CPU projection of a static map sub-samples to 256 columns for the same reason).
constexpr int kShMaxWidth = 128;

int mipLevels(int width) {
    int levels = 1;
    while ((width >> levels) > 0) ++levels;
    return levels;
}

}  // namespace

EnvironmentPass::EnvironmentPass()
    : toEquirect_(fullscreenProgram("environment: fish-eye to equirectangular",
                                    "passes/environment/fisheye_to_equirect.frag")),
      sh_(computeProgram("environment: SH9", "passes/environment/environment_sh.comp")),
      light_("environment light", sizeof(GpuEnvironment)) {
    uCameraFromWorld_ = toEquirect_.uniformLocation("cameraFromWorld");
    uFocal_ = toEquirect_.uniformLocation("focal");
    uDistortion_ = toEquirect_.uniformLocation("distortion");
    uK3_ = toEquirect_.uniformLocation("distortionK3");
    uKb_ = toEquirect_.uniformLocation("kannalaBrandt");
    uImageSize_ = toEquirect_.uniformLocation("imageSize");
    uMaxTheta_ = toEquirect_.uniformLocation("maxTheta");
    uGain_ = toEquirect_.uniformLocation("gain");
    uLevel_ = sh_.uniformLocation("level");
}

void EnvironmentPass::setup(PassBuilder& b) const {
    b.read(kSceneEnvironmentMap);
    b.readOptional(kEnvironmentCamera);  // imported only while the environment is live
    b.create(kEnvironmentMap, {GL_RGBA16F, SizeRule::Scene, Storage::Persistent});
    b.createBuffer(kEnvironmentLight, SizeRule::Scene, /*persistent=*/true);
}

PassDecision EnvironmentPass::decide(const FrameContext& ctx) const {
    const EnvironmentInput& e = ctx.environment;
    if (e.live)
        return {true, fmt::format("environment camera frame t = {:.3f} s -> {}x{} map", e.time,
                                  ctx.options.environment.mapWidth,
                                  ctx.options.environment.mapWidth / 2)};
    return {true, ctx.scene.hasEnvironment() ? "the scene's static environment map"
                                             : "no environment (black)"};
}

bool EnvironmentPass::upToDate(const FrameContext& ctx) const {
    return doneGeneration_ == ctx.environment.generation;
}

void EnvironmentPass::resize(const FrameContext& ctx) {
    if (!ctx.environment.live) return;  // the static map needs no target
    const int w = ctx.options.environment.mapWidth, h = w / 2;
    if (map_.width() == w && map_.height() == h) return;
    map_ = gl::Texture::create2D("environment map (live)", w, h, GL_RGBA16F, mipLevels(w));
    map_.setFilter(GL_LINEAR_MIPMAP_LINEAR, GL_LINEAR);
    glTextureParameteri(map_.id(), GL_TEXTURE_WRAP_S, GL_REPEAT);
    glTextureParameteri(map_.id(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    fbo_ = gl::Framebuffer("environment map fbo");
    fbo_.attachColor(0, map_);
    fbo_.finalize(1);
}

void EnvironmentPass::execute(FrameContext& ctx, PassResources& res) {
    if (ctx.environment.live) {
        executeLive(ctx, res);
    } else {
        // The scene's map as it is, and the SH9 GpuScene projected on the CPU.
        GpuEnvironment g{};
        const std::vector<glm::vec3>& sh = ctx.scene.environmentSH();
        for (int i = 0; i < 9; ++i) g.envSH[i] = glm::vec4(sh[size_t(i)], 0.0f);
        g.envRotation = ctx.scene.environmentRotation();
        g.envSeenFraction = 1.0f;
        light_.upload(&g, sizeof(g));
        res.publish(kEnvironmentMap, res.texture(kSceneEnvironmentMap));
    }
    res.publish(kEnvironmentLight, light_);
    doneGeneration_ = ctx.environment.generation;
}

void EnvironmentPass::executeLive(FrameContext& ctx, PassResources& res) {
    const EnvironmentInput& e = ctx.environment;
    MR_CHECK(res.has(kEnvironmentCamera),
             "live environment without an imported environment-camera frame");
    const CameraIntrinsics& K = e.camera;
    const bool kb = K.model == DistortionModel::KannalaBrandt;
    double maxTheta = kb ? K.maxFisheyeTheta : std::min(K.maxFisheyeTheta, 1.5707963267948966);
    if (e.reachDeg > 0) maxTheta = std::min(maxTheta, e.reachDeg * 3.14159265358979 / 180.0);

    fbo_.bind();
    ctx.beginFullscreen(toEquirect_, map_.width(), map_.height());
    const glm::mat3 cameraFromWorld(glm::transpose(e.T_world_camera.rotationMatrix()));
    glUniformMatrix3fv(uCameraFromWorld_, 1, GL_FALSE, glm::value_ptr(cameraFromWorld));
    glUniform4f(uFocal_, float(K.fx), float(K.fy), float(K.cx), float(K.cy));
    glUniform4f(uDistortion_, float(K.coeff(0)), float(K.coeff(1)), float(K.coeff(2)),
                float(K.coeff(3)));
    glUniform1f(uK3_, float(K.coeff(4)));
    glUniform1i(uKb_, kb ? 1 : 0);
    glUniform2f(uImageSize_, float(K.width), float(K.height));
    glUniform1f(uMaxTheta_, float(maxTheta));
    glUniform3f(uGain_, e.gain.r, e.gain.g, e.gain.b);
    glBindTextureUnit(kUnitEnvFisheye, res.texture(kEnvironmentCamera).id());
    ctx.drawFullscreenTriangle();
    // The levels below serve the SH9 projection now and blurrier lookups (rough reflections).
    glGenerateTextureMipmap(map_.id());

    if (e.lightFreeSHValid) {
        // Lights found in this frame are placed as lights of their own: the diffuse light is
        // the SH9 of the map without them (projected on the CPU, render/EnvironmentLights.h).
        GpuEnvironment g{};
        for (int i = 0; i < 9; ++i) g.envSH[i] = glm::vec4(e.lightFreeSH[size_t(i)], 0.0f);
        g.envRotation = 0.0f;
        g.envSeenFraction = e.lightFreeSeenFraction;
        light_.upload(&g, sizeof(g));
        res.publish(kEnvironmentMap, map_);
        return;
    }
    int level = 0;
    while ((map_.width() >> level) > kShMaxWidth) ++level;
    sh_.use();
    glUniform1i(uLevel_, level);
    glBindTextureUnit(kUnitEnvShSource, map_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindingEnvironment, light_.id());
    glDispatchCompute(1, 1, 1);
    glMemoryBarrier(GL_UNIFORM_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    res.publish(kEnvironmentMap, map_);
}

// Registered in render/PassList.cpp.
std::unique_ptr<RenderPass> makeEnvironmentPass(const PassInit&) {
    return std::make_unique<EnvironmentPass>();
}

}  // namespace mirage::render

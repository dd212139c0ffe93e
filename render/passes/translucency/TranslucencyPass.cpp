#include "render/passes/translucency/TranslucencyPass.h"

#include <cstring>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "render/FrameGraph.h"
#include "render/translucency/VoxelNumberMap.h"

namespace mirage::render {

TranslucencyPass::TranslucencyPass(const Scene& scene, const GpuScene& gpu,
                                   const RendererOptions& options) {
    if (!options.translucency) {
        why_ = "translucency off (RendererOptions::translucency)";
        return;
    }
    std::vector<translucency::TranslucentObject> objects = translucency::translucentObjects(scene);
    if (objects.empty()) {
        why_ = "no translucent object in the scene";
        return;
    }
    for (size_t k = 1; k < objects.size(); ++k)
        spdlog::warn(
            "translucent object '{}': the real-time renderer shades only the first translucent "
            "object ('{}') with its voxel number map; this one is drawn as an opaque surface of "
            "its base colour",
            objects[k].name, objects[0].name);
    const translucency::TranslucentObject& object = objects[0];
    translucency::VnmSettings settings;
    settings.resolution = options.vnmResolution;
    settings.cacheDir = options.vnmCacheDir;
    const translucency::VoxelNumberMap map = translucency::VoxelNumberMap::build(object, settings);
    const auto& sv = map.surface();
    const size_t S = sv.size();
    surfaceVoxels_ = int(S);
    why_ = "translucent '" + object.name + "': " + std::to_string(S) + " surface voxels";
    envTransmittance_ = translucency::hemisphericalTransmittance(object.medium.ior);
    albedoOverPi_ = translucency::effectiveAlbedo(object.medium.albedo) / 3.14159265358979f;

    // Header (gridOrigin, gridDims, gridParams: translucency.glsl) + one int per cell.
    const std::vector<int32_t>& numbers = map.numbers();
    std::vector<int32_t> grid(12 + numbers.size());
    const glm::vec4 origin(map.origin(), map.voxelSize());
    const glm::ivec4 dims(map.dims(), int(S));
    const glm::vec4 params(object.medium.ior, 0.0f, 0.0f, 0.0f);
    std::memcpy(&grid[0], &origin, 16);
    std::memcpy(&grid[4], &dims, 16);
    std::memcpy(&grid[8], &params, 16);
    std::memcpy(&grid[12], numbers.data(), numbers.size() * sizeof(int32_t));
    grid_ = gl::Buffer("translucent grid", grid.size() * sizeof(int32_t), grid.data(), 0);

    std::vector<glm::vec4> voxels(2 * S);
    for (size_t i = 0; i < S; ++i) {
        voxels[2 * i] =
            glm::vec4(sv[i].position, sv[i].exterior ? sv[i].area * sv[i].kernelScale : 0.0f);
        voxels[2 * i + 1] = glm::vec4(sv[i].normal, 0.0f);
    }
    voxels_ = gl::Buffer("translucent voxels", voxels.size() * sizeof(glm::vec4), voxels.data(), 0);
    // Half floats two per uint (the shader's unpackHalf2x16), padded to whole uints.
    std::vector<uint16_t> lut = map.tauHalf();
    if (lut.size() % 2) lut.push_back(0);
    lut_ = gl::Buffer("translucent tau LUT", lut.size() * sizeof(uint16_t), lut.data(), 0);
    irradiance_ = gl::Buffer("translucent irradiance", 2 * S * sizeof(glm::vec4), nullptr, 0);
    radiance_ = gl::Buffer("translucent radiance", 2 * S * sizeof(glm::vec4), nullptr, 0);
    program_ = computeProgram("translucency", "passes/translucency/translucency.comp",
                              gpu.lightingDefines());
}

void TranslucencyPass::setup(PassBuilder& b) const {
    b.read(Resource::EnvironmentLight);
    b.readOptional(Resource::ShadowMaps);  // none: no light has a caster (unshadowed)
    b.readOptional(Resource::ShadowMapsReal);
    b.readOptional(Resource::ShadowGlass);
    b.readOptional(Resource::ShadowGlassReal);
    b.writeBuffer(Resource::TranslucentGrid, SizeRule::Scene, true);
    b.writeBuffer(Resource::TranslucentRadiance, SizeRule::Scene);
}

PassDecision TranslucencyPass::decide(const FrameContext& ctx) const {
    if (surfaceVoxels_ > 0 && upToDate(ctx))
        return {true,
                "nothing changed: lights, environment and translucent objects as in the last "
                "frame"};
    return {surfaceVoxels_ > 0, why_};
}

std::string TranslucencyPass::inputKey(const FrameContext& ctx) const {
    return ctx.staticKey + fmt::format("|env {} {} {}", ctx.environment.generation,
                                       int(ctx.environment.live), ctx.frame.envOrigin);
}

bool TranslucencyPass::upToDate(const FrameContext& ctx) const {
    return ctx.options.reuseStaticPasses && !doneKey_.empty() && doneKey_ == inputKey(ctx);
}

void TranslucencyPass::execute(FrameContext& ctx, PassResources& res) {
    program_.use();
    ctx.bindFrameBlocks();
    glBindBufferBase(GL_UNIFORM_BUFFER, kBindingEnvironment,
                     res.buffer(Resource::EnvironmentLight).id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindingTranslucentGrid, grid_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindingTranslucentVoxels, voxels_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindingTranslucentLut, lut_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindingTranslucentIrradiance, irradiance_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindingTranslucentRadiance, radiance_.id());
    glBindTextureUnit(kUnitTranslucencyShadowAll,
                      res.textureOr(Resource::ShadowMaps, ctx.farShadowTexture()).id());
    glBindTextureUnit(kUnitTranslucencyShadowReal,
                      res.textureOr(Resource::ShadowMapsReal, ctx.farShadowTexture()).id());
    glBindTextureUnit(kUnitTranslucencyGlassAll,
                      res.textureOr(Resource::ShadowGlass, ctx.noGlassTexture()).id());
    glBindTextureUnit(kUnitTranslucencyGlassReal,
                      res.textureOr(Resource::ShadowGlassReal, ctx.noGlassTexture()).id());
    glUniform1f(program_.uniformLocation("envTransmittance"), envTransmittance_);
    glUniform3fv(program_.uniformLocation("albedoOverPi"), 1, &albedoOverPi_[0]);
    const GLuint groups = GLuint((surfaceVoxels_ + 63) / 64);
    glUniform1i(program_.uniformLocation("stage"), 0);
    glDispatchCompute(groups, 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    glUniform1i(program_.uniformLocation("stage"), 1);
    glDispatchCompute(groups, 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    res.publish(Resource::TranslucentGrid, grid_);
    res.publish(Resource::TranslucentRadiance, radiance_);
    doneKey_ = inputKey(ctx);
}

}  // namespace mirage::render

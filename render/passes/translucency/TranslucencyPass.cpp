#include "render/passes/translucency/TranslucencyPass.h"

#include <cstring>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "core/Error.h"
#include "render/FrameGraph.h"
#include "render/PassRegistry.h"
#include "render/passes/environment/EnvironmentPass.h"
#include "render/passes/shadow/ShadowPass.h"
#include "render/translucency/VoxelNumberMap.h"

namespace mirage::render {

namespace {

// One translucent object in the header of the grid buffer (translucency.glsl
// TranslucentObjectGpu, std430): 6 vec4.
struct ObjectHeader {
    glm::vec4 gridOrigin;    // world corner of cell (0,0,0), voxel edge (m)
    glm::ivec4 gridDims;     // cells per axis, S
    glm::vec4 params;        // ior, F_t over the cosine-weighted hemisphere, smooth lookup 1/0,
                             // mean extinction at the surface voxels (1/m)
    glm::ivec4 offsets;      // first cell number, first surface voxel, first LUT entry, 0
    glm::vec4 albedoOverPi;  // a_eff / pi, 0
    glm::vec4 falloff;       // k of the kernel e^{-k tau} per channel, 0
};
static_assert(sizeof(ObjectHeader) == 96);

}  // namespace

TranslucencyPass::TranslucencyPass(const Scene& scene, const GpuScene& gpu,
                                   const RendererOptions& options) {
    if (!options.translucency.enabled) {
        why_ = "translucency off (RendererOptions::translucency.enabled)";
        return;
    }
    std::vector<translucency::TranslucentObject> objects = translucency::translucentObjects(scene);
    if (objects.empty()) {
        why_ = "no translucent object in the scene";
        return;
    }
    for (size_t k = kMaxObjects; k < objects.size(); ++k)
        spdlog::warn(
            "translucent object '{}': the real-time renderer shades at most {} translucent "
            "objects with voxel number maps; this one is drawn as an opaque surface of its base "
            "colour",
            objects[k].name, kMaxObjects);
    if (objects.size() > size_t(kMaxObjects)) objects.resize(size_t(kMaxObjects));

    translucency::VnmSettings settings;
    settings.resolution = options.translucency.vnmResolution;
    settings.cacheDir = options.translucency.vnmCacheDir;
    settings.kernel = options.translucency.diffusionKernel ? translucency::VnmKernel::Diffusion
                                                           : translucency::VnmKernel::Extinction;
    settings.surface = options.translucency.meshSurface ? translucency::VnmSurface::Mesh
                                                        : translucency::VnmSurface::Occupancy;
    std::vector<ObjectHeader> headers;
    std::vector<int32_t> numbers;
    std::vector<glm::vec4> voxels;
    std::vector<uint16_t> lut;
    size_t lutTotal = 0;
    for (const translucency::TranslucentObject& object : objects) {
        const translucency::VoxelNumberMap map =
            translucency::VoxelNumberMap::build(object, settings);
        const auto& sv = map.surface();
        const size_t S = sv.size();
        // Every map was checked against the limit alone; together they must fit it too.
        lutTotal += map.lutBytes();
        if (lutTotal > settings.maxLutBytes)
            throw Error(fmt::format(
                "voxel number maps: the LUTs of the first {} translucent objects need {} MiB "
                "together, more than the limit of {} MiB; lower the voxel resolution "
                "(vnmResolution) or make fewer objects translucent",
                headers.size() + 1, lutTotal >> 20, settings.maxLutBytes >> 20));
        ObjectHeader h{};
        h.gridOrigin = glm::vec4(map.origin(), map.voxelSize());
        h.gridDims = glm::ivec4(map.dims(), int(S));
        // The mean extinction at the surface voxels' centres: a chord too short to meet a
        // second surface voxel crosses the medium there (translucency.glsl).
        double surfaceSigma = 0;
        for (const auto& v : sv) surfaceSigma += object.medium.sigmaT(v.position);
        h.params = glm::vec4(object.medium.ior,
                             translucency::hemisphericalTransmittance(object.medium.ior),
                             options.translucency.smoothLookup ? 1.0f : 0.0f,
                             S ? float(surfaceSigma / double(S)) : 0.0f);
        h.offsets = glm::ivec4(int(numbers.size()), surfaceVoxels_, int(lut.size()), 0);
        h.albedoOverPi = glm::vec4(translucency::VnmShading::radianceScale(
                                       map, object.medium, options.translucency.measuredAlbedo),
                                   0);
        h.falloff = glm::vec4(map.falloff(), 0);
        headers.push_back(h);
        numbers.insert(numbers.end(), map.numbers().begin(), map.numbers().end());
        for (size_t i = 0; i < S; ++i) {
            voxels.emplace_back(sv[i].position, 0.0f);
            voxels.emplace_back(sv[i].normal,
                                options.translucency.smoothLookup ? sv[i].nearScale : 1.0f);
            voxels.emplace_back(sv[i].exterior ? sv[i].area * sv[i].kernelScale : glm::vec3(0.0f),
                                0.0f);
        }
        lut.insert(lut.end(), map.tauHalf().begin(), map.tauHalf().end());
        surfaceVoxels_ += int(S);
        objectVoxels_.push_back(int(S));
        why_ += (why_.empty() ? "" : ", ") + fmt::format("'{}': {} surface voxels", object.name, S);
    }
    why_ = fmt::format("{} translucent object(s): ", headers.size()) + why_;

    // Grid buffer: the object count, kMaxObjects headers, then every object's voxel numbers.
    const size_t headerBytes = 16 + kMaxObjects * sizeof(ObjectHeader);
    std::vector<uint8_t> grid(headerBytes + numbers.size() * sizeof(int32_t), 0);
    const glm::ivec4 count(int(headers.size()), 0, 0, 0);
    std::memcpy(grid.data(), &count, 16);
    std::memcpy(grid.data() + 16, headers.data(), headers.size() * sizeof(ObjectHeader));
    std::memcpy(grid.data() + headerBytes, numbers.data(), numbers.size() * sizeof(int32_t));
    grid_ = gl::Buffer("translucent grid", grid.size(), grid.data(), 0);
    voxels_ = gl::Buffer("translucent voxels", voxels.size() * sizeof(glm::vec4), voxels.data(), 0);
    // Half floats two per uint (the shader's unpackHalf2x16), padded to whole uints.
    if (lut.size() % 2) lut.push_back(0);
    lut_ = gl::Buffer("translucent tau LUT", lut.size() * sizeof(uint16_t), lut.data(), 0);
    const size_t total = size_t(surfaceVoxels_);
    irradiance_ = gl::Buffer("translucent irradiance", 2 * total * sizeof(glm::vec4), nullptr, 0);
    radiance_ = gl::Buffer("translucent radiance", 2 * total * sizeof(glm::vec4), nullptr, 0);
    program_ = computeProgram("translucency", "passes/translucency/translucency.comp",
                              gpu.lightingDefines());
}

void TranslucencyPass::setup(PassBuilder& b) const {
    b.read(kEnvironmentLight);
    b.readOptional(kShadowMaps);  // none: no light has a caster (unshadowed)
    b.readOptional(kShadowMapsReal);
    b.readOptional(kShadowGlass);
    b.readOptional(kShadowGlassReal);
    b.createBuffer(kTranslucentGrid, SizeRule::Scene, true);
    b.createBuffer(kTranslucentRadiance, SizeRule::Scene);
    b.createBuffer(kTranslucentLut, SizeRule::Scene, true);
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
    return ctx.options.graph.reuseStaticPasses && !doneKey_.empty() && doneKey_ == inputKey(ctx);
}

void TranslucencyPass::execute(FrameContext& ctx, PassResources& res) {
    program_.use();
    ctx.bindFrameBlocks();
    glBindBufferBase(GL_UNIFORM_BUFFER, kBindingEnvironment, res.buffer(kEnvironmentLight).id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindingTranslucentGrid, grid_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindingTranslucentVoxels, voxels_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindingTranslucentLut, lut_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindingTranslucentIrradiance, irradiance_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindingTranslucentRadiance, radiance_.id());
    glBindTextureUnit(kUnitTranslucencyShadowAll,
                      res.textureOr(kShadowMaps, ctx.farShadowTexture()).id());
    glBindTextureUnit(kUnitTranslucencyShadowReal,
                      res.textureOr(kShadowMapsReal, ctx.farShadowTexture()).id());
    glBindTextureUnit(kUnitTranslucencyGlassAll,
                      res.textureOr(kShadowGlass, ctx.noGlassTexture()).id());
    glBindTextureUnit(kUnitTranslucencyGlassReal,
                      res.textureOr(kShadowGlassReal, ctx.noGlassTexture()).id());
    const GLint stage = program_.uniformLocation("stage");
    const GLint object = program_.uniformLocation("objectIndex");
    // Stage 0 (irradiance) of every object, then stage 1 (radiance out) of every object: one
    // invocation per surface voxel of the object.
    for (int s = 0; s < 2; ++s) {
        glUniform1i(stage, s);
        for (size_t k = 0; k < objectVoxels_.size(); ++k) {
            glUniform1i(object, int(k));
            glDispatchCompute(GLuint((objectVoxels_[k] + 63) / 64), 1, 1);
        }
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    }
    res.publish(kTranslucentGrid, grid_);
    res.publish(kTranslucentRadiance, radiance_);
    res.publish(kTranslucentLut, lut_);
    doneKey_ = inputKey(ctx);
}

// Registered in render/PassList.cpp.
std::unique_ptr<RenderPass> makeTranslucencyPass(const PassInit& init) {
    return std::make_unique<TranslucencyPass>(init.scene, init.gpuScene, init.options);
}

}  // namespace mirage::render

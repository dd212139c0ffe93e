#pragma once
// The voxel number map at run time (docs/translucency.md): for each of the scene's translucent
// objects (up to kMaxObjects, each with its own map), the irradiance at its surface voxels from
// every light (visibility from the shadow maps) and the environment (SH irradiance), then the
// radiance leaving every surface voxel, L_o = (1/pi) a_eff sum_i E_i A_i c_i e^{-k tau(i, o)}
// (compute, two dispatches), for L_rv and L_r. The precomputation (surface voxels, tau LUT) is the
// CPU VoxelNumberMap's, built (or read from its disk cache) when the renderer is created and
// uploaded once. direct.frag shades the object's pixels from the result. Runs only when the scene
// has a translucent object, and dispatches only when a light, the shadow maps or the environment
// changed since the last frame.
#include <memory>
#include <string>
#include <vector>

#include "core/scene/Scene.h"
#include "render/RenderPass.h"

namespace mirage::render {

// SSBOs of the first translucent object (docs/translucency.md). TranslucentGrid: header + the
// voxel number of every grid cell (persistent, uploaded once); TranslucentRadiance: per surface
// voxel the radiance (1/pi) a_eff sum E A c e^{-k tau} leaving it before the exit F_t, S vec4 for
// L_rv then S vec4 for L_r.
inline constexpr Resource kTranslucentGrid{"TranslucentGrid"};
inline constexpr Resource kTranslucentRadiance{"TranslucentRadiance"};
// The optical thickness between every two surface voxels of each object (half floats; persistent,
// uploaded once): the chord a camera ray crosses (direct.frag's see-through).
inline constexpr Resource kTranslucentLut{"TranslucentLut"};

class TranslucencyPass final : public RenderPass {
public:
    TranslucencyPass(const Scene& scene, const GpuScene& gpu, const RendererOptions& options);
    const char* name() const override { return "translucency"; }
    void setup(PassBuilder& b) const override;
    PassDecision decide(const FrameContext& ctx) const override;
    // True while nothing its result depends on changed since it last ran: the lights and the
    // shadow maps (FrameContext::staticKey), the environment (its generation and origin); the
    // objects are static. The graph then republishes the last radiance without dispatching.
    bool upToDate(const FrameContext& ctx) const override;
    void resize(const FrameContext& /*ctx*/) override {}  // sized by the scene, once
    void execute(FrameContext& ctx, PassResources& res) override;

    // Translucent objects with a voxel number map; further ones are drawn opaque (a warning).
    static constexpr int kMaxObjects = 8;
    int surfaceVoxels() const { return surfaceVoxels_; }  // all objects'
    int objectCount() const { return int(objectVoxels_.size()); }

private:
    std::string inputKey(const FrameContext& ctx) const;
    std::string why_;      // decide()'s reason
    std::string doneKey_;  // inputKey() of the last run
    int surfaceVoxels_ = 0;
    std::vector<int> objectVoxels_;  // S per object
    gl::Program program_;
    gl::Buffer grid_, voxels_, lut_, irradiance_, radiance_;
};

}  // namespace mirage::render

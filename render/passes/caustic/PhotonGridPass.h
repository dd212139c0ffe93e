#pragma once
// The world-space photon grid (docs/caustics.md, "Caustics seen in reflections and
// refractions"): the photons of the photon G-buffers sorted into a hashed uniform grid of their
// receiver hits by three compute steps (count, prefix sum, scatter), so that the specular light
// pass can gather the caustic at reflected and refracted hits, points the camera does not see
// and the camera-space caustic buffer therefore cannot hold. Camera-independent like the photon
// G-buffers: rebuilt only when they are.
#include "render/RenderPass.h"

namespace mirage::render {

// A hashed uniform grid of the photons' receiver hits, for the caustics seen in reflections and
// refractions. PhotonGrid: uint per slot, a slot per hash cell and level of the photon map's
// nested lattices (kPhotonGridSlots counts, then kPhotonGridSlots + 1 first indices);
// PhotonRecords: GpuPhoton per photon, sorted by cell, then by level.
inline constexpr Resource kPhotonGrid{"PhotonGrid"};
inline constexpr Resource kPhotonRecords{"PhotonRecords"};

class PhotonGridPass final : public RenderPass {
public:
    PhotonGridPass();
    const char* name() const override { return "photongrid"; }
    void setup(PassBuilder& b) const override;
    PassDecision decide(const FrameContext& ctx) const override;
    void resize(const FrameContext& ctx) override;
    void execute(FrameContext& ctx, PassResources& res) override;
    bool cameraIndependent() const override { return true; }

    // Whether this frame gathers caustic photons at the reflected / refracted hits, and why
    // (shared with the specular light pass's report).
    static PassDecision gatherDecision(const FrameContext& ctx);
    // Whether the scene can ever gather (a spot light and a mirror or glass object, caustics and
    // the gather on): the specular light pass compiles its gather variant only then.
    static bool sceneCanGather(const GpuScene& scene, const RendererOptions& options);
    // Grid cell edge (m): twice RendererOptions::caustic.gatherRadius.
    static float cellSize(const RendererOptions& options) {
        return 2.0f * options.caustic.gatherRadius;
    }

private:
    gl::Program count_, scan_, scatter_;
    gl::Buffer grid_, records_;
    size_t capacity_ = 0;  // photon records allocated
};

}  // namespace mirage::render

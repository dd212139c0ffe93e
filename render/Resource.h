#pragma once
// What the frame graph (render/FrameGraph.h) hands from pass to pass: named resources, each
// declared by the pass that creates it (a constant in that pass's header, e.g. kGBufferPosition
// in render/passes/gbuffer/GBufferPass.h) or by the renderer as an import (render/FrameImports.h).
// There is no central list: a new pass declares its resources in its own folder.
#include <cstddef>
#include <cstring>

#include <epoxy/gl.h>

namespace mirage::render {

// A resource's name. Two Resources are the same resource when their names are equal.
struct Resource {
    const char* name;
    constexpr explicit Resource(const char* n) : name(n) {}
    friend bool operator==(Resource a, Resource b) {
        return a.name == b.name || std::strcmp(a.name, b.name) == 0;
    }
    friend bool operator!=(Resource a, Resource b) { return !(a == b); }
};

inline const char* resourceName(Resource r) {
    return r.name;
}

// How a resource's size follows the frame (checked when a pass publishes a texture, and what the
// graph allocates transient textures at).
enum class SizeRule {
    Canvas,       // the render canvas (CameraProjection::canvasWidth/Height)
    Camera,       // the camera image
    Gather,       // canvas / RendererOptions::indirect.scale per axis, rounded up
    GatherTiles,  // Gather rounded up to a multiple of the interleave K (deinterleaved tiles)
    ShadowAtlas,  // shadowMapSize^2, one layer per shadow layer of the frame plan
    // ShadowAtlas and then one layer per focused virtual-occluder map (FramePlan::focusLayers)
    FocusedShadowAtlas,
    RsmAtlas,    // rsmSize^2, one layer per shadow layer of the frame plan
    IsmAtlas,    // tilesPerRow(vplCount) * ismTileSize, square
    Impostor,    // impostorResolution^2, layers per specular object / impostor
    CausticMap,  // causticMapSize^2, one layer per caustic spot light of the frame plan
    Vpl,         // buffer: vplCount entries
    Scene,       // sized by the scene (imports, impostor tables)
};
const char* sizeRuleName(SizeRule s);

// Who allocates a resource's texture, and how long its contents live.
enum class Storage {
    // The graph allocates it from the descriptor for the frames the pass runs, and may give the
    // same texture to another transient resource of the same descriptor whose lifetime (its
    // writer to its last reader this frame) does not overlap. The pass gets it with
    // PassResources::target() and must write every texel it publishes each time it runs
    // (another resource may have used the texture in between).
    Transient,
    // The pass allocates it (in resize()) and publishes it; the graph never reuses it.
    PassOwned,
    // The pass allocates it and keeps its contents across frames (temporal history, impostors).
    Persistent,
};

// A texture's descriptor: GL internal format, size rule, storage.
struct TextureDesc {
    GLenum format = GL_RGBA16F;
    SizeRule size = SizeRule::Canvas;
    Storage storage = Storage::Transient;
};

// One version of a resource, as the graph's builder returns it: create() gives version 0, each
// modify() the next. A read through a handle must name the newest version at that point of the
// frame (a modified resource's older versions are gone: reading one is a bug in the pass order).
struct TextureHandle {
    Resource resource{""};
    int version = -1;
    bool valid() const { return version >= 0; }
};

// GL internal format as text ("RGBA16F"; buffers: "SSBO").
const char* formatName(GLenum format);
// Bytes per texel of a colour or depth format (0 for unknown formats and buffers).
size_t bytesPerTexel(GLenum format);

}  // namespace mirage::render

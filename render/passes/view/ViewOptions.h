#pragma once
// Options of the resource view (render/passes/view/ResourceViewPass.h), kept in the renderer's
// per-pass option set (RendererOptions::passes.get<ViewOptions>()).
#include <string>

#include "render/PassOptions.h"

namespace mirage::render {

struct ViewOptions {
    // The frame resource shown in place of the composite, as the passes name it ("GBufferNormal",
    // "LRv", "MotionVelocity", ...; docs/realtime-renderer.md lists each pass's). Empty: off, the
    // composite as rendered.
    std::string resource;
    // Multiplies the texels before display: depths in metres and small radiances need it.
    float scale = 1.0f;

    void validate() const {
        checkOption(scale > 0.0f && scale <= 1e6f, "view.scale", "in (0, 1e6]", scale);
    }
};

}  // namespace mirage::render

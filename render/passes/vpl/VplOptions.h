#pragma once
// Options of the virtual point lights (render/passes/vpl, docs/realtime-renderer.md).
#include "render/PassOptions.h"

namespace mirage::render {

struct VplOptions {
    int count = 256;  // total VPLs per frame, split over the lights with RSMs
    // A VPL whose reflective-shadow-map sample lands on a mirror or glass continues to the
    // reflected or refracted photon's receiver (Knecht 2013 Sec. 5.2), for spot lights with
    // photon G-buffers (caustics on); false: it stays on the mirror / glass, which scatters no
    // diffuse light (the VPL is dark).
    bool throughSpecular = true;
    // Each frame's VPLs from the same Hammersley set shifted by a per-frame offset (a Cranley-
    // Patterson rotation along the R2 sequence of the frame index), so that the GI filter's
    // temporal smoothing averages several VPL sets where the camera holds still; the VPLs and
    // the imperfect shadow maps are then placed every frame instead of being reused while the
    // scene is static. The Halton choice between a reflected and a refracted photon moves along
    // its sequence too (each taken about every second frame, as Knecht 2013 Sec. 5.2 has it).
    // false: the same VPLs every frame (no VPL flicker).
    bool temporalRotation = false;

    void validate() const {
        checkOption(count >= 0 && count <= 16384, "vpl.count", "0..16384", count);
    }
};

}  // namespace mirage::render

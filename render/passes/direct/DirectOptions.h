#pragma once
// Options of the direct-light pass (render/passes/direct).
#include "render/PassOptions.h"

namespace mirage::render {

struct DirectOptions {
    // false (the default): `direct` (with the GI upsample) and the composite's diffuse variant skip
    // the pixels that show a mirror or glass object (their light comes from the specular passes;
    // FrameContext::drawFullscreenTriangleOutsideSpecular). true: they shade them too (tests
    // compare the two).
    bool onSpecularPixels = false;
    // true: in frames with VPL light the pass also writes the direct light alone (DirectRv /
    // DirectR; two more canvas targets), besides the GI solutions LRv / LR it sums with the
    // upsampled indirect light. false (the default): DirectRv / DirectR exist only in frames
    // without VPL light, where they are LRv / LR.
    bool keepDirectLight = false;
    // true (the default): rough mirrors, metals and glass (roughness above 0.05) show the punctual
    // lights' GGX highlight (direct.frag's MIRAGE_ROUGH_HIGHLIGHT variant over their pixels; the
    // composite adds it to their specular light; docs/specular.md, "The glossy highlight").
    // false: their light comes from the mirror / refracted ray alone, which never meets a
    // punctual light (no highlight).
    bool roughHighlight = true;
    // true (the default; with roughHighlight): rough glass also lets the punctual lights' light
    // through towards the eye, scattered by its rough surfaces where the light enters it
    // (rough_transmission.glsl; docs/specular.md, "Rough light"). false: only its reflection.
    bool roughTransmission = true;

    void validate() const {}
};

}  // namespace mirage::render

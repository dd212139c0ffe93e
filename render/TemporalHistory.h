#pragma once
// The temporal history of a pass that smooths a buffer over frames (the GI filter's indirect
// light, the caustic buffer, the specular-hit light L'): which of its two ping-pong buffers is
// written this frame, and the one rule for when last frame's buffer may be blended in. The frame's
// part of the rule is the Renderer's (FrameContext::historyValid: not the first frame, no cut /
// seek / tracking loss, no object moved); the pass's part is here: it ran in the previous frame
// (a pass skipped or culled for a frame holds an older history) and its blend weight is above 0.
// The per-texel part (reprojection with last frame's camera, the surface-distance test) is the
// GLSL of render/temporal.glsl.
#include <string>

#include "render/FrameContext.h"

namespace mirage::render {

class TemporalHistory {
public:
    // The history written in the previous frame may be blended into this one, with weight
    // `blend` (the history's share, 0 = off).
    bool usable(const FrameContext& ctx, float blend) const;
    // What the report says: "temporal history used" or "temporal history reset (why)".
    std::string note(const FrameContext& ctx, float blend) const;
    // The ping-pong slot written this frame, and the one read as history.
    int writeSlot() const { return current_; }
    int readSlot() const { return 1 - current_; }
    // Call once the frame's history is written: the slots swap for the next frame.
    void written(const FrameContext& ctx);
    // The buffers were (re)allocated: they hold no history until the next write.
    void drop() { lastWrittenFrame_ = -2; }

private:
    int current_ = 0;
    int lastWrittenFrame_ = -2;  // FrameContext::frameIndex of the last write
};

}  // namespace mirage::render

#include "render/TemporalHistory.h"

namespace mirage::render {

bool TemporalHistory::usable(const FrameContext& ctx, float blend) const {
    return blend > 0.0f && ctx.historyValid && lastWrittenFrame_ == ctx.frameIndex - 1;
}

std::string TemporalHistory::note(const FrameContext& ctx, float blend) const {
    if (usable(ctx, blend)) return "temporal history used";
    if (!(blend > 0.0f)) return "temporal history reset (smoothing off)";
    if (!ctx.historyValid) return "temporal history reset (" + ctx.historyResetReason + ")";
    return "temporal history reset (the pass did not run in the previous frame)";
}

void TemporalHistory::written(const FrameContext& ctx) {
    lastWrittenFrame_ = ctx.frameIndex;
    current_ = 1 - current_;
}

}  // namespace mirage::render

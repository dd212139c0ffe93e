#pragma once
// Where the virtual objects stand while the user moves them in the live window (keys, drag): a
// change moves them at once (in place where the renderer can), and is saved beside the scene,
// with a renderer built anew when the move could not be made in place, only once the keys have
// rested (a rebuild takes about a second on llvmpipe; a save per key repeat would be wasted).
#include <chrono>

#include "core/scene/ScenePlacement.h"

namespace mirage::app {

class PlacementEditor {
public:
    using Clock = std::chrono::steady_clock;
    static constexpr double kRestSeconds = 0.3;

    explicit PlacementEditor(ScenePlacement placement) : placement_(placement) {}

    // A change at `now`; `inPlace`: the renderer moved the objects already (false: it needs a
    // new renderer). Returns false, changing nothing, when `p` is where the objects stand.
    bool change(const ScenePlacement& p, bool inPlace, Clock::time_point now) {
        if (p == placement_) return false;
        placement_ = p;
        changedAt_ = now;
        pending_ = true;
        needsRebuild_ = needsRebuild_ || !inPlace;
        return true;
    }
    // True once per change, when the keys have rested kRestSeconds and no drag is going on:
    // the caller saves the placement, and builds a renderer anew if rebuildNeeded().
    bool settle(Clock::time_point now, bool dragging) {
        if (!pending_ || dragging ||
            std::chrono::duration<double>(now - changedAt_).count() <= kRestSeconds)
            return false;
        pending_ = false;
        rebuild_ = needsRebuild_;
        needsRebuild_ = false;
        return true;
    }
    bool rebuildNeeded() const { return rebuild_; }  // of the change settle() returned
    bool pending() const { return pending_; }
    const ScenePlacement& placement() const { return placement_; }

private:
    ScenePlacement placement_;
    Clock::time_point changedAt_{};
    bool pending_ = false, needsRebuild_ = false, rebuild_ = false;
};

}  // namespace mirage::app

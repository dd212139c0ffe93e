#pragma once
// The tag board's plane, on which the virtual objects are placed (core/scene/ScenePlacement.h).
#include <glm/glm.hpp>

#include "core/Error.h"
#include "core/scene/ScenePlacement.h"
#include "tracking/Board.h"

namespace mirage::app {

// The centre of the board's tags, the normal out of the page (a tag's +Z points into the page,
// docs/tracking.md) and the board's +X. Throws for a board without tags.
inline PlacementPlane boardPlane(const tracking::Board& board) {
    if (board.tags.empty()) throw Error("placement: the board has no tags to place objects on");
    PlacementPlane p;
    p.point = glm::dvec3(0.0);
    for (const auto& t : board.tags) p.point += t.T_world_tag.translation;
    p.point /= double(board.tags.size());
    const glm::dmat3 r = board.tags.front().T_world_tag.rotationMatrix();
    p.normal = -r[2];
    p.axisU = r[0];
    return p;
}

}  // namespace mirage::app

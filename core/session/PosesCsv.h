#pragma once
// Reads the poses CSV `mirage track` writes (docs/tracking.md): a header naming at least
// frame,t,state,reason,tx,ty,tz,qw,qx,qy,qz (any order, extra columns ignored), then one row per
// frame. The pose is T_world_camera (translation metres, unit quaternion scalar first); a row
// without a pose leaves tx empty.
#include <filesystem>
#include <map>
#include <optional>
#include <string>

#include "core/math/Pose.h"

namespace mirage {

struct PoseRow {
    std::string state, reason;
    std::optional<Pose> pose;
};

// Rows by frame number. Throws FileError (naming the line) on a missing column, a number that
// does not parse, a negative frame number, NaN or infinity, or a quaternion whose length is not
// 1 +- 0.001 (a zero quaternion would otherwise become the identity, a confident wrong pose).
std::map<int, PoseRow> readPosesCsv(const std::filesystem::path& path);
// The same on the file's text; `source` names it in messages.
std::map<int, PoseRow> parsePosesCsv(const std::string& text, const std::string& source);

}  // namespace mirage

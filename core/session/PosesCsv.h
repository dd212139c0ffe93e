#pragma once
// Reads the poses CSV `mirage track` writes (docs/tracking.md): a header naming at least
// frame,t,state,reason,tx,ty,tz,qw,qx,qy,qz (any order, extra columns ignored), then one row per
// frame. The pose is T_world_camera (translation metres, unit quaternion scalar first); a row
// without a pose leaves tx empty.
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/math/Pose.h"

namespace mirage {

struct PoseRow {
    std::string state, reason;
    std::optional<Pose> pose;
    int line = 0;  // in the file it was read from (0: not read from a file)
};

// Largest pose translation component accepted from a file, metres: a camera 100 km from the
// world origin is a unit mix-up or garbage (1e300 made error reports print "inf m (-nan %)").
inline constexpr double kMaxPoseMetres = 1e5;

// The states `mirage track` writes (tracking::TrackingState's names).
bool isTrackingStateName(const std::string& state);
// The same names as a list for messages ("ok, no_tags, ...").
std::string trackingStateNames();

// Rows by frame number. Throws FileError (naming the line and the field) on a missing column, a
// number that does not parse, a negative or repeated frame number, a state that is not one of
// the tracking states, an ok row without a pose, NaN, infinity or a translation beyond
// kMaxPoseMetres, or a quaternion whose length is not 1 +- 0.001 (a zero quaternion would
// otherwise become the identity, a confident wrong pose).
std::map<int, PoseRow> readPosesCsv(const std::filesystem::path& path);
// The same on the file's text; `source` names it in messages.
std::map<int, PoseRow> parsePosesCsv(const std::string& text, const std::string& source);

// Every row's frame must be one of the session's frames (Session::frames): a poses file for
// other footage would put every pose on the wrong frame. Throws FileError(source, "line N, field
// frame: ...") for the first that is not.
struct Session;
void checkPoseFrames(const std::map<int, PoseRow>& poses, const Session& session,
                     const std::string& source);

// Writing the same format: the header line and one row (each with '\n'). Numbers in their
// shortest exact form, so a pose read back is the pose written, bit for bit (a replay of the
// poses renders what the writer rendered); the reason quoted when it needs it; a row without
// a pose leaves the seven pose fields empty.
std::string posesCsvHeader();
std::string posesCsvRow(int frame, double t, const PoseRow& row);
// A double in its shortest exact decimal form ("0.1", "1e-07").
std::string exactDecimal(double v);

}  // namespace mirage

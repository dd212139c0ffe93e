#pragma once
// frames.csv of a session (docs/session.md): one header line naming the columns, then one row
// per frame. Columns are found by name, so extra columns and any column order are accepted:
//   frame                      video frame position (0-based), strictly increasing
//   t_<camera>                 seconds, one per camera of session.json ("t" alone = main camera)
//   gt_tx,gt_ty,gt_tz          ground-truth T_world_camera translation, metres (optional)
//   gt_qw,gt_qx,gt_qy,gt_qz    its rotation as a unit quaternion (optional; empty = unknown)
// Lines starting with '#' are comments.
#include <filesystem>
#include <string>
#include <vector>

#include "core/session/Session.h"

namespace mirage {

// Parses frames.csv for the given cameras. Bad rows are skipped and described in `warnings`
// ("frames.csv line 12: ..."). Throws FileError if the file cannot be read or has no usable
// header (no 'frame' column).
std::vector<FrameRecord> readFramesCsv(const std::filesystem::path& path, double fps,
                                       const std::vector<std::string>& cameraNames,
                                       std::vector<std::string>& warnings);

std::string framesCsvHeader(const std::vector<std::string>& cameraNames);
// One line (with '\n'); doubles in their shortest exact form.
std::string framesCsvRow(const FrameRecord& r);

}  // namespace mirage

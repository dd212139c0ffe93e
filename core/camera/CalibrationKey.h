#pragma once
// One top-level key of a calibration file (OpenCV YAML), added or replaced in place: what a
// command that measures one more property of a calibrated camera (its radiometry against the
// main camera, its response curve) writes, keeping everything else in the file.
#include <filesystem>
#include <string>

namespace mirage {

// Writes `key: value` (value on one line: a number, a flow sequence `[ ... ]` or a flow mapping
// `{ ... }`) at the end of the file, after dropping an earlier line of that key written the same
// way; atomically (temporary file + rename). Throws FileError when the file cannot be read.
void setCalibrationKey(const std::filesystem::path& calibrationFile, const std::string& key,
                       const std::string& value);

}  // namespace mirage

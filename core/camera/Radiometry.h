#pragma once
// The radiometric ratio of a second camera (the environment camera) to the main camera, stored
// in that camera's calibration file under the key `radiometry_to_main` (docs/formats.md): per
// channel (R, G, B), the factor that takes its linearised pixel values into the main camera's
// linear units (its exposure and white balance relative to the main camera's).
#include <filesystem>
#include <optional>

#include <glm/glm.hpp>

namespace mirage {

// Unset when the file has no such key. Throws mirage::FileError naming the key when it is not
// three finite positive numbers, or when the file cannot be read as YAML.
std::optional<glm::dvec3> loadRadiometryToMain(const std::filesystem::path& calibrationFile);
// Adds or replaces the key in an existing calibration file (atomically); the rest is kept.
void saveRadiometryToMain(const std::filesystem::path& calibrationFile, const glm::dvec3& ratio);

}  // namespace mirage

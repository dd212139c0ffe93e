#include "core/camera/CalibrationKey.h"

#include <fstream>
#include <regex>
#include <sstream>

#include <fmt/format.h>

#include "core/Error.h"
#include "core/session/AtomicFile.h"

namespace mirage {

void setCalibrationKey(const std::filesystem::path& file, const std::string& key,
                       const std::string& value) {
    std::ifstream in(file);
    if (!in) throw FileError(file.string(), "cannot read the calibration file");
    std::stringstream ss;
    ss << in.rdbuf();
    std::string text = std::regex_replace(ss.str(), std::regex("\n" + key + ":[^\n]*"), "");
    if (!text.empty() && text.back() != '\n') text += '\n';
    text += fmt::format("{}: {}\n", key, value);
    writeFileAtomically(file, text);
}

}  // namespace mirage

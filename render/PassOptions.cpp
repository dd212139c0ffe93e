#include "render/PassOptions.h"

#include "core/Error.h"

namespace mirage::render {

void failOption(const std::string& name, const std::string& range, const std::string& got) {
    throw Error("renderer option " + name + " must be " + range + ", got " + got);
}

}  // namespace mirage::render

#include "render/passes/rough/RoughOptions.h"

namespace mirage::render {

const char* roughRefractionMethodName(RoughRefractionMethod m) {
    switch (m) {
        case RoughRefractionMethod::Filter:
            return "filter";
        case RoughRefractionMethod::Lean:
            return "lean";
        case RoughRefractionMethod::Gsr:
            return "gsr";
    }
    return "?";
}

}  // namespace mirage::render

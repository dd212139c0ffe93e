#include "render/passes/shadow/ShadowOptions.h"

namespace mirage::render {

const char* shadowFilterName(ShadowFilter f) {
    switch (f) {
        case ShadowFilter::Bilinear:
            return "off";
        case ShadowFilter::Pcf:
            return "pcf";
    }
    return "?";
}

}  // namespace mirage::render

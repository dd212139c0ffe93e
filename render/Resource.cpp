#include "render/Resource.h"

namespace mirage::render {

const char* sizeRuleName(SizeRule s) {
    switch (s) {
        case SizeRule::Canvas:
            return "canvas";
        case SizeRule::Camera:
            return "camera image";
        case SizeRule::Gather:
            return "canvas/scale";
        case SizeRule::GatherTiles:
            return "canvas/scale, K tiles";
        case SizeRule::ShadowAtlas:
            return "shadow atlas";
        case SizeRule::FocusedShadowAtlas:
            return "shadow atlas + focused maps";
        case SizeRule::RsmAtlas:
            return "RSM atlas";
        case SizeRule::IsmAtlas:
            return "ISM atlas";
        case SizeRule::Impostor:
            return "impostor layers";
        case SizeRule::CausticMap:
            return "caustic map";
        case SizeRule::Vpl:
            return "VPL count";
        case SizeRule::Scene:
            return "scene";
    }
    return "?";
}

const char* formatName(GLenum format) {
    switch (format) {
        case 0:
            return "SSBO";
        case GL_RGBA32F:
            return "RGBA32F";
        case GL_RGBA16F:
            return "RGBA16F";
        case GL_RGBA8:
            return "RGBA8";
        case GL_RG32F:
            return "RG32F";
        case GL_R32F:
            return "R32F";
        case GL_R32UI:
            return "R32UI";
        case GL_RGBA32UI:
            return "RGBA32UI";
        case GL_SRGB8_ALPHA8:
            return "SRGB8_ALPHA8";
        case GL_DEPTH_COMPONENT32F:
            return "DEPTH32F";
    }
    return "other";
}

size_t bytesPerTexel(GLenum format) {
    switch (format) {
        case GL_RGBA32F:
        case GL_RGBA32UI:
            return 16;
        case GL_RGBA16F:
        case GL_RG32F:
            return 8;
        case GL_RGBA8:
        case GL_SRGB8_ALPHA8:
        case GL_R32F:
        case GL_R32UI:
        case GL_DEPTH_COMPONENT32F:
            return 4;
    }
    return 0;
}

}  // namespace mirage::render

#include "render/Resource.h"

namespace mirage::render {

const char* resourceName(Resource r) {
    static const char* const names[kResourceCount] = {
        "CameraImage",
        "SceneEnvironmentMap",
        "EnvironmentCamera",
        "EnvironmentMap",
        "EnvironmentLight",
        "GBufferPosition",
        "GBufferNormal",
        "GBufferAlbedo",
        "GBufferEmissive",
        "ShadowMaps",
        "ShadowMapsReal",
        "ShadowGlass",
        "ShadowGlassReal",
        "RsmFlux",
        "RsmNormal",
        "RsmPosition",
        "Vpls",
        "ImperfectShadowMaps",
        "ImperfectShadowMapsReal",
        "TranslucentGrid",
        "TranslucentRadiance",
        "DirectRv",
        "DirectR",
        "IndirectRv",
        "IndirectR",
        "GiHistoryRv",
        "GiHistoryR",
        "GatherLight",
        "LRv",
        "LR",
        "ImpostorCubePosition",
        "ImpostorCubeNormal",
        "ImpostorCubeAlbedo",
        "ImpostorCubeEmissive",
        "ImpostorDepth",
        "ImpostorNormal",
        "ImpostorAlbedo",
        "ImpostorEmissive",
        "ImpostorRecords",
        "ImpostorObjects",
        "BackFacePosition",
        "BackFaceNormal",
        "RealSurfaces",
        "ReflectionGBuffer",
        "ReflectionNormal",
        "ReflectionAlbedo",
        "ReflectionEmissive",
        "ReflectionWeight",
        "RefractionGBuffer",
        "RefractionNormal",
        "RefractionAlbedo",
        "RefractionEmissive",
        "RefractionWeight",
        "SpecularMask",
        "SpecularRv",
        "SpecularR",
        "SpecularRReflection",
        "Lenv",
        "FuzzySpecularRv",
        "FuzzySpecularR",
        "FuzzySpecularRReflection",
        "FuzzyLenv",
        "FuzzyReflectionVideo",
        "RoughSpecularRv",
        "RoughSpecularR",
        "RoughSpecularRReflection",
        "RoughLenv",
        "RoughVideo",
        "PhotonHitRefl",
        "PhotonPowerRefl",
        "PhotonHitRefr",
        "PhotonPowerRefr",
        "PhotonSurfaceRefl",
        "PhotonSurfaceRefr",
        "PhotonGrid",
        "PhotonRecords",
        "CausticRv",
        "CausticR",
        "CausticHistoryRv",
        "CausticHistoryR",
        "Composite",
        "CompositeSrgb",
    };
    const int i = int(r);
    return i >= 0 && i < kResourceCount ? names[i] : "?";
}

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

}  // namespace mirage::render

#pragma once
// The resources the renderer imports into every frame (render/FrameGraph.h importTexture): what
// comes from outside the frame's passes.
#include "render/Resource.h"

namespace mirage::render {

// The camera frame, sRGB8 texture sampled as linear (camera image size).
inline constexpr Resource kCameraImage{"CameraImage"};
// The scene's static equirectangular map, linear (1x1 black: none).
inline constexpr Resource kSceneEnvironmentMap{"SceneEnvironmentMap"};
// The environment (fish-eye) camera's newest frame, sRGB8; imported only while a live
// environment is set (Renderer::setEnvironmentCamera).
inline constexpr Resource kEnvironmentCamera{"EnvironmentCamera"};

}  // namespace mirage::render

#pragma once
// Options of the live environment (render/passes/environment, docs/environment.md).
#include "render/GpuTypes.h"
#include "render/PassOptions.h"

namespace mirage::render {

struct EnvironmentOptions {
    // Width of the equirectangular map built from each environment-camera frame (height =
    // width / 2).
    int mapWidth = 512;
    // The real light, placed (docs/environment.md, "Light estimation"): at most this many of the
    // dominant lights found in each live environment frame become shadow-casting REAL
    // directional lights, and the diffuse environment light is projected from the map without
    // them (render/EnvironmentLights.h). 0: none (the environment's SH9 holds all its light).
    // The scene's lights plus these are at most kMaxLights.
    int lights = 0;
    int lightMapWidth = 256;  // width of the map the lights are found on (CPU, height = width / 2)

    void validate() const {
        checkOption(mapWidth >= 16 && mapWidth <= 4096 && mapWidth % 2 == 0, "environment.mapWidth",
                    "even, 16..4096 texels", mapWidth);
        checkOption(lights >= 0 && lights <= kMaxLights, "environment.lights",
                    "0.." + std::to_string(kMaxLights), lights);
        checkOption(lightMapWidth >= 16 && lightMapWidth <= 2048 && lightMapWidth % 2 == 0,
                    "environment.lightMapWidth", "even, 16..2048 texels", lightMapWidth);
    }
};

}  // namespace mirage::render

#pragma once
// Can the footage support a reconstruction? Multi-view stereo needs the camera to move sideways:
// frames filmed from one point (a pure rotation, a tripod pan) see every surface along the same
// rays and hold no depth. The check runs before any work and says what to record instead.
#include <string>

#include "render/reconstruction/Footage.h"

namespace mirage::reconstruction {

struct FootageCheckOptions {
    int minFrames = 8;  // tracked frames (state ok)
    // The largest angle (degrees) between the rays from the board's centre to two camera
    // centres: below it the views are too alike for stereo depth (an orbit of 30 degrees gives
    // about 30; a hand-held pan from one spot under 2).
    double minParallaxDeg = 8.0;
};

struct FootageCheck {
    bool ok = false;
    std::string problem;  // why not, and what to record instead (empty when ok)
    int frames = 0;
    double parallaxDeg = 0;      // as defined in the options
    double maxBaselineM = 0;     // largest distance between two camera centres
    double medianDistanceM = 0;  // camera centre to the board's centre
};

FootageCheck checkFootage(const Footage& footage, const FootageCheckOptions& options = {});

}  // namespace mirage::reconstruction

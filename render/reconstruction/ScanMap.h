#pragma once
// The scan seen from above (docs/reconstruction.md, "The scan map"): what `mirage proxies` and
// `mirage live --scan` write beside the rebuilt scene as SCENE.scan.svg, so a user sees at a
// glance whether the scan covered the table: the table's rebuilt extent, the board, each
// object's footprint, every camera position the reconstruction used with the direction it looked
// in, and the fitted spot light with the point its axis meets the table. Drawn in the board's
// plane coordinates (metres, docs/reconstruction.md), the side the cameras stood on at the
// bottom; the caption states the frames, the arc the cameras spanned and how far down they
// looked.
#include <string>

#include "render/reconstruction/Footage.h"
#include "render/reconstruction/ProxyReconstruction.h"

namespace mirage::reconstruction {

// The SVG document (<svg ...>...</svg>).
std::string scanMapSvg(const Footage& footage, const Reconstruction& reconstruction);

}  // namespace mirage::reconstruction

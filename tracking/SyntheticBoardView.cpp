#include "tracking/SyntheticBoardView.h"

#include <algorithm>

#include "core/Error.h"
#include "core/camera/TexturedPlaneRenderer.h"

namespace mirage::tracking {

cv::Mat renderSyntheticBoardView(const Board& board, const BoardRaster& texture,
                                 const CameraIntrinsics& camera, const Pose& T_world_camera,
                                 const SyntheticViewOptions& options) {
    if (!board.sheet) throw Error("synthetic view: the board has no sheet to render");
    if (!camera.isValid()) throw Error("synthetic view: invalid camera intrinsics");
    const BoardSheet& sh = *board.sheet;
    // The sheet frame has its origin at the page centre; raster row 0 lies at the smallest sheet y.
    PlaneTexture plane;
    plane.image = texture.image;
    plane.metresPerTexelX = texture.metresPerPixelX;
    plane.metresPerTexelY = texture.metresPerPixelY;
    plane.originMetres = {-0.5 * sh.width, -0.5 * sh.height};
    plane.filter = PlaneTexture::Filter::Bilinear;
    PlaneShading shading;
    shading.black = options.ink;
    shading.white = options.paper;
    shading.background = options.background;
    const TexturedPlaneRenderer renderer(camera, std::max(1, options.supersample));
    return renderer.render(plane, T_world_camera.inverse() * sh.T_world_sheet, shading);
}

}  // namespace mirage::tracking

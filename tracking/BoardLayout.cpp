#include "tracking/BoardLayout.h"

#include <cmath>
#include <cstdio>

#include "core/Error.h"
#include "tracking/TagFamily.h"

namespace mirage::tracking {

Pose BoardLayout::tableSheetPose() {
    // Columns are the sheet axes expressed in the world: +x -> +X, +y -> +Z, +z -> -Y.
    return Pose::fromRotationTranslation(glm::dmat3(1, 0, 0, 0, 0, 1, 0, -1, 0), glm::dvec3(0.0));
}

Board BoardLayout::makeBoard() const {
    if (rows < 1 || cols < 1 || rows > kBoardMaxTagsPerSide || cols > kBoardMaxTagsPerSide)
        throw Error("board layout: rows and cols must be 1.." +
                    std::to_string(kBoardMaxTagsPerSide));
    if (!kBoardTagSizeM.contains(tagSize) || !kBoardGapM.contains(gap) ||
        !kBoardMarginM.contains(margin))
        throw Error("board layout: tag size must be in " + kBoardTagSizeM.text() + ", gap in " +
                    kBoardGapM.text() + " and margin in " + kBoardMarginM.text() + " metres");
    const TagFamily fam(family);
    if (firstId < 0 || firstId + rows * cols > fam.codeCount())
        throw Error("board layout: ids " + std::to_string(firstId) + ".." +
                    std::to_string(firstId + rows * cols - 1) + " do not fit family " + family +
                    " (0.." + std::to_string(fam.codeCount() - 1) + ")");
    // The tag image extends (totalWidth - widthAtBorder)/2 cells beyond the detection corners
    // (tag36h11: one white cell). Neighbouring tag images must not overlap, and the page must hold
    // the outer ones.
    const double cell = tagSize / fam.widthAtBorder();
    const double ring = 0.5 * (fam.totalWidth() - fam.widthAtBorder()) * cell;
    if (gap + 1e-12 < 2 * ring)
        throw Error("board layout: gap " + std::to_string(gap) + " m is narrower than the tags' " +
                    "quiet zone; use at least " + std::to_string(2 * ring) + " m");
    if (margin + 1e-12 < ring)
        throw Error("board layout: margin must be at least " + std::to_string(ring) + " m");

    const double gridW = cols * tagSize + (cols - 1) * gap;
    const double gridH = rows * tagSize + (rows - 1) * gap;
    // Footer: a scale bar (whole centimetres, up to 10 cm) and a one-line caption.
    const double barGap = std::max(0.004, 0.5 * gap), barThickness = 0.003, captionH = 0.006;
    const double pageW = gridW + 2 * margin;
    const double pageH = gridH + 2 * margin + barGap + barThickness + captionH;

    Board b;
    b.family = family;
    BoardSheet sheet;
    sheet.width = pageW;
    sheet.height = pageH;
    sheet.T_world_sheet = T_world_sheet;
    sheet.scaleBarLength = std::min(0.10, std::floor((pageW - 2 * margin) * 100.0 + 1e-9) / 100.0);
    sheet.scaleBarThickness = barThickness;
    sheet.scaleBarTopLeft = {margin, margin + gridH + barGap};
    char caption[256];
    std::snprintf(caption, sizeof caption,
                  "mirage board %s %dx%d  tag %.1f mm  gap %.1f mm  ids %d-%d  scale bar %.0f mm",
                  family.c_str(), rows, cols, tagSize * 1000, gap * 1000, firstId,
                  firstId + rows * cols - 1, sheet.scaleBarLength * 1000);
    sheet.caption = caption;
    b.sheet = sheet;

    for (int r = 0; r < rows; ++r) {
        for (int c = 0; c < cols; ++c) {
            // Tag centre in page metres (origin top-left), then in the sheet frame (origin centre).
            const double px = margin + c * (tagSize + gap) + 0.5 * tagSize;
            const double py = margin + r * (tagSize + gap) + 0.5 * tagSize;
            Pose T_sheet_tag;
            T_sheet_tag.translation = {px - 0.5 * pageW, py - 0.5 * pageH, 0.0};
            BoardTag t;
            t.id = firstId + r * cols + c;
            t.size = tagSize;
            t.T_world_tag = T_world_sheet * T_sheet_tag;
            b.tags.push_back(t);
        }
    }
    return b;
}

}  // namespace mirage::tracking

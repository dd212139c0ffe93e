#include "tracking/BoardImage.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

#include <opencv2/imgproc.hpp>

#include "core/Error.h"
#include "core/image/ImageIO.h"
#include "tracking/TagFamily.h"

namespace mirage::tracking {

std::vector<InkRect> boardInk(const Board& board) {
    if (!board.sheet)
        throw Error(
            "board has no printable sheet (only planar boards made by `mirage board` "
            "or with a \"sheet\" entry can be drawn)");
    const BoardSheet& sh = *board.sheet;
    const TagFamily fam(board.family);
    const Pose T_sheet_world = sh.T_world_sheet.inverse();
    std::vector<InkRect> ink;
    for (const auto& tag : board.tags) {
        const Pose T_sheet_tag = T_sheet_world * tag.T_world_tag;
        if (rotationAngleBetween(T_sheet_tag.rotation, glm::dquat(1, 0, 0, 0)) > 1e-6 ||
            std::abs(T_sheet_tag.translation.z) > 1e-7)
            throw Error("tag " + std::to_string(tag.id) +
                        " is not upright in the sheet plane; the board cannot be printed");
        const cv::Mat code = fam.codeImage(tag.id);
        const double cell = tag.size / fam.widthAtBorder();
        const double x0 = T_sheet_tag.translation.x + 0.5 * sh.width - 0.5 * code.cols * cell;
        const double y0 = T_sheet_tag.translation.y + 0.5 * sh.height - 0.5 * code.rows * cell;
        for (int r = 0; r < code.rows; ++r) {
            for (int c = 0; c < code.cols;) {
                if (code.at<uint8_t>(r, c) >= 128) {
                    ++c;
                    continue;
                }
                int end = c;
                while (end < code.cols && code.at<uint8_t>(r, end) < 128) ++end;
                ink.push_back({x0 + c * cell, y0 + r * cell, (end - c) * cell, cell});
                c = end;
            }
        }
    }
    if (sh.scaleBarLength > 0) {
        // Alternating black/white centimetres inside a thin black frame.
        const double x = sh.scaleBarTopLeft.x, y = sh.scaleBarTopLeft.y;
        const double len = sh.scaleBarLength, th = sh.scaleBarThickness, line = 0.0002;
        for (int k = 0; (k + 1) * 0.01 <= len + 1e-9; k += 2)
            ink.push_back({x + k * 0.01, y, std::min(0.01, len - k * 0.01), th});
        ink.push_back({x, y, len, line});
        ink.push_back({x, y + th - line, len, line});
        ink.push_back({x, y, line, th});
        ink.push_back({x + len - line, y, line, th});
    }
    return ink;
}

BoardRaster renderBoard(const Board& board, double pixelsPerMetre, bool caption) {
    if (!(pixelsPerMetre > 0) || !std::isfinite(pixelsPerMetre))
        throw Error("board image: pixels per metre must be > 0");
    const auto ink = boardInk(board);
    const BoardSheet& sh = *board.sheet;
    const int cols = std::max(1, int(std::lround(sh.width * pixelsPerMetre)));
    const int rows = std::max(1, int(std::lround(sh.height * pixelsPerMetre)));
    if (double(cols) * rows > 4e8) throw Error("board image: too many pixels; lower the DPI");
    const double sx = cols / sh.width, sy = rows / sh.height;  // pixels per metre, exact
    // Linear white coverage, reduced by each rectangle's exact area overlap with each pixel.
    cv::Mat white(rows, cols, CV_32F, cv::Scalar(1.0f));
    for (const auto& r : ink) {
        const double x0 = r.x * sx, x1 = (r.x + r.w) * sx, y0 = r.y * sy, y1 = (r.y + r.h) * sy;
        const int i0 = std::max(0, int(std::floor(y0))), i1 = std::min(rows, int(std::ceil(y1)));
        const int j0 = std::max(0, int(std::floor(x0))), j1 = std::min(cols, int(std::ceil(x1)));
        for (int i = i0; i < i1; ++i) {
            const double cy = std::min(y1, i + 1.0) - std::max(y0, double(i));
            if (cy <= 0) continue;
            float* row = white.ptr<float>(i);
            for (int j = j0; j < j1; ++j) {
                const double cx = std::min(x1, j + 1.0) - std::max(x0, double(j));
                if (cx > 0) row[j] -= float(cx * cy);
            }
        }
    }
    BoardRaster out;
    out.image.create(rows, cols, CV_8UC1);
    // Linear coverage -> sRGB 8-bit through a 4096-entry table (exact to the 8-bit output).
    std::vector<uint8_t> encode(4097);
    for (int k = 0; k <= 4096; ++k)
        encode[size_t(k)] = uint8_t(std::lround(255.0f * linearToSrgb(float(k) / 4096.0f)));
    for (int i = 0; i < rows; ++i) {
        const float* src = white.ptr<float>(i);
        uint8_t* dst = out.image.ptr<uint8_t>(i);
        for (int j = 0; j < cols; ++j)
            dst[j] = encode[size_t(std::lround(4096.0f * std::clamp(src[j], 0.0f, 1.0f)))];
    }
    if (caption && !sh.caption.empty() && sh.scaleBarThickness > 0) {
        // Caption under the scale bar, about 2.5 mm tall.
        const double textH = 0.0025 * sy;
        const double scale = textH / 22.0;  // FONT_HERSHEY_SIMPLEX cap height is ~22 px at 1.0
        const int thickness = std::max(1, int(std::lround(scale * 1.5)));
        const cv::Point org(
            int(sh.scaleBarTopLeft.x * sx),
            int((sh.scaleBarTopLeft.y + sh.scaleBarThickness + 0.0015) * sy + textH));
        if (scale > 0.15)
            cv::putText(out.image, sh.caption, org, cv::FONT_HERSHEY_SIMPLEX, scale, cv::Scalar(0),
                        thickness, cv::LINE_AA);
    }
    out.metresPerPixelX = sh.width / cols;
    out.metresPerPixelY = sh.height / rows;
    return out;
}

void writeBoardPng(const std::filesystem::path& path, const Board& board, double dpi) {
    if (!(dpi > 0)) throw Error("board PNG: --dpi must be > 0");
    const BoardRaster r = renderBoard(board, dpi / 0.0254);
    cv::Mat bgr;
    cv::cvtColor(r.image, bgr, cv::COLOR_GRAY2BGR);
    writeBgr8(path, bgr);
}

namespace {
std::string pdfEscape(const std::string& s) {
    std::string o;
    for (char c : s) {
        if (c == '(' || c == ')' || c == '\\') o += '\\';
        o += (static_cast<unsigned char>(c) < 128) ? c : '?';
    }
    return o;
}
}  // namespace

void writeBoardPdf(const std::filesystem::path& path, const Board& board) {
    const auto ink = boardInk(board);
    const BoardSheet& sh = *board.sheet;
    const double ptPerM = 72.0 / 0.0254;
    const double pageW = sh.width * ptPerM, pageH = sh.height * ptPerM;
    // Content stream: one filled path of all ink rectangles (a single fill avoids the hairline
    // seams viewers draw between separately anti-aliased adjacent rectangles). PDF's origin is
    // the bottom-left, +y up, so page y flips.
    std::string content = "0 g\n";
    char buf[160];
    for (const auto& r : ink) {
        std::snprintf(buf, sizeof buf, "%.4f %.4f %.4f %.4f re\n", r.x * ptPerM,
                      pageH - (r.y + r.h) * ptPerM, r.w * ptPerM, r.h * ptPerM);
        content += buf;
    }
    content += "f\n";
    if (!sh.caption.empty() && sh.scaleBarThickness > 0) {
        const double fontPt = 0.0025 * ptPerM / 0.72;  // Helvetica cap height ~0.72 em
        std::snprintf(buf, sizeof buf, "BT /F1 %.3f Tf %.4f %.4f Td (", fontPt,
                      sh.scaleBarTopLeft.x * ptPerM,
                      pageH - (sh.scaleBarTopLeft.y + sh.scaleBarThickness + 0.004) * ptPerM);
        content += buf + pdfEscape(sh.caption) + ") Tj ET\n";
    }

    std::vector<std::string> objects;
    objects.push_back("<< /Type /Catalog /Pages 2 0 R >>");
    objects.push_back("<< /Type /Pages /Kids [3 0 R] /Count 1 >>");
    std::snprintf(buf, sizeof buf,
                  "<< /Type /Page /Parent 2 0 R /MediaBox [0 0 %.4f %.4f] /Contents 4 0 R "
                  "/Resources << /Font << /F1 5 0 R >> >> >>",
                  pageW, pageH);
    objects.push_back(buf);
    objects.push_back("<< /Length " + std::to_string(content.size()) + " >>\nstream\n" + content +
                      "endstream");
    objects.push_back("<< /Type /Font /Subtype /Type1 /BaseFont /Helvetica >>");

    std::string pdf = "%PDF-1.4\n%\xE2\xE3\xCF\xD3\n";
    std::vector<size_t> offsets;
    for (size_t i = 0; i < objects.size(); ++i) {
        offsets.push_back(pdf.size());
        pdf += std::to_string(i + 1) + " 0 obj\n" + objects[i] + "\nendobj\n";
    }
    const size_t xref = pdf.size();
    pdf += "xref\n0 " + std::to_string(objects.size() + 1) + "\n0000000000 65535 f \n";
    for (size_t off : offsets) {
        std::snprintf(buf, sizeof buf, "%010zu 00000 n \n", off);
        pdf += buf;
    }
    pdf += "trailer\n<< /Size " + std::to_string(objects.size() + 1) +
           " /Root 1 0 R >>\nstartxref\n" + std::to_string(xref) + "\n%%EOF\n";

    const auto tmp = path.string() + ".tmp";
    {
        std::ofstream out(tmp, std::ios::binary);
        if (!out) throw FileError(path.string(), "cannot write PDF");
        out.write(pdf.data(), std::streamsize(pdf.size()));
        if (!out) throw FileError(path.string(), "write failed");
    }
    std::error_code ec;
    std::filesystem::rename(tmp, path, ec);
    if (ec) throw FileError(path.string(), "cannot rename temporary file: " + ec.message());
}

}  // namespace mirage::tracking

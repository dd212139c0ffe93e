#include <gtest/gtest.h>

#include <fstream>

#include <opencv2/imgcodecs.hpp>

#include "core/Error.h"
#include "tests/support/TestSupport.h"
#include "tracking/Board.h"
#include "tracking/BoardImage.h"
#include "tracking/BoardLayout.h"
#include "tracking/TagFamily.h"

namespace mirage::tracking {
namespace {

TEST(TagFamily, Tag36h11Geometry) {
    TagFamily f("tag36h11");
    EXPECT_EQ(f.codeCount(), 587);
    EXPECT_EQ(f.widthAtBorder(), 8);
    EXPECT_EQ(f.totalWidth(), 10);
    cv::Mat code = f.codeImage(0);
    ASSERT_EQ(code.rows, 10);
    // Outer ring white (quiet zone), next ring black (the detection border).
    EXPECT_EQ(code.at<uint8_t>(0, 0), 255);
    EXPECT_EQ(code.at<uint8_t>(1, 1), 0);
    EXPECT_EQ(code.at<uint8_t>(8, 5), 0);
    EXPECT_THROW(f.codeImage(587), Error);
    EXPECT_THROW(TagFamily("tag99h1"), Error);
}

TEST(BoardLayout, TableBoardLiesOnXZPlaneFacingUp) {
    BoardLayout l;
    l.rows = 2;
    l.cols = 3;
    l.tagSize = 0.05;
    l.gap = 0.0125;
    l.firstId = 10;
    Board b = l.makeBoard();
    ASSERT_EQ(b.tags.size(), 6u);
    EXPECT_TRUE(b.isPlanar());
    EXPECT_EQ(b.tags[0].id, 10);
    EXPECT_EQ(b.tags[5].id, 15);
    for (const auto& t : b.tags) {
        auto c = t.cornersInWorld();
        for (const auto& p : c) EXPECT_NEAR(p.y, 0.0, 1e-12);
        EXPECT_NEAR(glm::length(c[1] - c[0]), 0.05, 1e-12);
        // Tag +Z (into the tag) is world -Y: the printed side faces up.
        EXPECT_NEAR((t.T_world_tag.rotation * glm::dvec3(0, 0, 1)).y, -1.0, 1e-12);
        // corner 3 (top-left) -> corner 2 (top-right) runs along world +X,
        // corner 3 (top-left) -> corner 0 (bottom-left) along world +Z (towards the reader).
        EXPECT_NEAR(glm::dot(glm::normalize(c[2] - c[3]), glm::dvec3(1, 0, 0)), 1.0, 1e-12);
        EXPECT_NEAR(glm::dot(glm::normalize(c[0] - c[3]), glm::dvec3(0, 0, 1)), 1.0, 1e-12);
    }
    // Row-major from the top-left: id 11 is right of id 10; id 13 is one row nearer the reader.
    EXPECT_NEAR(b.tags[1].T_world_tag.translation.x - b.tags[0].T_world_tag.translation.x, 0.0625,
                1e-12);
    EXPECT_NEAR(b.tags[3].T_world_tag.translation.z - b.tags[0].T_world_tag.translation.z, 0.0625,
                1e-12);
}

TEST(BoardLayout, RejectsUnprintableLayouts) {
    BoardLayout l;
    l.gap = 0.001;  // narrower than two white cells of 4 mm
    EXPECT_THROW(l.makeBoard(), Error);
    l = BoardLayout();
    l.firstId = 580;
    EXPECT_THROW(l.makeBoard(), Error);
    l = BoardLayout();
    l.rows = 0;
    EXPECT_THROW(l.makeBoard(), Error);
}

TEST(Board, JsonRoundTrip) {
    Board b = BoardLayout().makeBoard();
    auto dir = test::outputDir("board_roundtrip");
    b.save(dir / "b.json");
    Board r = Board::load(dir / "b.json");
    ASSERT_EQ(r.tags.size(), b.tags.size());
    ASSERT_TRUE(r.sheet.has_value());
    EXPECT_NEAR(r.sheet->width, b.sheet->width, 1e-12);
    for (size_t i = 0; i < b.tags.size(); ++i) {
        EXPECT_EQ(r.tags[i].id, b.tags[i].id);
        auto c0 = b.tags[i].cornersInWorld(), c1 = r.tags[i].cornersInWorld();
        for (int k = 0; k < 4; ++k) EXPECT_NEAR(glm::length(c0[k] - c1[k]), 0.0, 1e-12);
    }
}

TEST(Board, MalformedFilesNameTheField) {
    auto expectFieldError = [](const std::string& text, const std::string& field) {
        try {
            Board::parse(text, "bad.json");
            FAIL() << "no error for " << text;
        } catch (const FileError& e) {
            EXPECT_NE(std::string(e.what()).find("bad.json"), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
        }
    };
    const std::string pose = R"("T_world_tag": {"t": [0,0,0], "q_wxyz": [1,0,0,0]})";
    expectFieldError("{", "JSON");
    expectFieldError(R"({"family": "tag36h11"})", "tags");
    expectFieldError(R"({"family": "tag36h11", "tags": [{"id": 1, )" + pose + "}]}",
                     "tags[0].size");
    expectFieldError(R"({"family": "tag36h11", "tags": [{"id": 1, "size": -1, )" + pose + "}]}",
                     "tags[0].size");
    expectFieldError(
        R"({"family": "tag36h11", "tags": [{"id": 1, "size": 0.1, "T_world_tag": {"t": [0,0,0], "q_wxyz": [2,0,0,0]}}]})",
        "q_wxyz");
    expectFieldError(R"({"family": "tag36h11", "tags": [{"id": 1, "size": 0.1, )" + pose +
                         "}, {\"id\": 1, \"size\": 0.1, " + pose + "}]}",
                     "tags[1].id");
    expectFieldError(R"({"family": "nope", "tags": []})", "family");
    expectFieldError(R"({"family": "tag36h11", "tags": [{"id": 9999, "size": 0.1, )" + pose + "}]}",
                     "tags[0].id");
    EXPECT_THROW(Board::load("/nonexistent/board.json"), FileError);
}

TEST(Board, FileWithoutFamilyIsRefused) {
    // Taking tag36h11 when the family is missing tracked a board printed with another family as
    // no tags at all, or found codes of the wrong family: the family is required.
    const std::string text =
        R"({"tags": [{"id": 1, "size": 0.1, "T_world_tag": {"t": [0,0,0], "q_wxyz": [1,0,0,0]}}]})";
    try {
        Board::parse(text, "nofamily.json");
        FAIL() << "a board without a family was accepted";
    } catch (const FileError& e) {
        EXPECT_NE(std::string(e.what()).find("nofamily.json"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("'family'"), std::string::npos) << e.what();
    }
}

TEST(BoardImage, RasterHasExactPhysicalScale) {
    BoardLayout l;
    l.rows = 1;
    l.cols = 2;
    l.tagSize = 0.04;
    l.gap = 0.01;
    Board b = l.makeBoard();
    const double ppm = 2000;  // 0.5 mm per pixel: a tag cell (5 mm) is 10 pixels
    BoardRaster r = renderBoard(b, ppm, false);
    EXPECT_NEAR(r.metresPerPixelX * r.image.cols, b.sheet->width, 1e-12);
    // The first tag's black border starts one cell (5 mm) right of its white quiet zone, which
    // starts at the margin + ... : the black border's top-left is at (margin, margin).
    const int j = int(l.margin * ppm), i = int(l.margin * ppm);
    EXPECT_EQ(r.image.at<uint8_t>(i + 1, j + 1), 0);    // inside the black border
    EXPECT_EQ(r.image.at<uint8_t>(i - 2, j + 1), 255);  // white above it
    EXPECT_EQ(r.image.at<uint8_t>(i + 1, j - 2), 255);  // white left of it
    // Along a row through the top border, the black run spans the tag size (40 mm = 80 px).
    int black = 0;
    for (int x = j - 5; x < j + 95; ++x) black += r.image.at<uint8_t>(i + 3, x) == 0;
    EXPECT_EQ(black, 80);
}

TEST(BoardImage, PdfIsWellFormed) {
    Board b = BoardLayout().makeBoard();
    auto dir = test::outputDir("board_pdf");
    writeBoardPdf(dir / "b.pdf", b);
    std::ifstream in(dir / "b.pdf", std::ios::binary);
    std::string s((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    ASSERT_EQ(s.rfind("%PDF-1.4", 0), 0u);
    // startxref points at the xref table.
    auto sx = s.rfind("startxref\n");
    ASSERT_NE(sx, std::string::npos);
    size_t off = std::stoul(s.substr(sx + 10));
    EXPECT_EQ(s.compare(off, 4, "xref"), 0);
    // MediaBox is the sheet size in points.
    char box[64];
    std::snprintf(box, sizeof box, "/MediaBox [0 0 %.4f", b.sheet->width * 72 / 0.0254);
    EXPECT_NE(s.find(box), std::string::npos);
}

}  // namespace
}  // namespace mirage::tracking

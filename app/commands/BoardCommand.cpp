// `mirage board`: a printable planar AprilTag board (PDF or PNG) and its board file beside it
// (docs/tracking.md).
#include <algorithm>
#include <filesystem>
#include <memory>

#include <fmt/format.h>

#include "app/Command.h"
#include "app/NumberChecks.h"
#include "app/PathChecks.h"
#include "core/Error.h"
#include "core/Log.h"
#include "core/OutputFile.h"
#include "tracking/BoardImage.h"
#include "tracking/BoardLayout.h"

namespace mirage::app {
namespace {

// The largest PNG side written (pixels): a 1 m sheet at 600 dpi.
constexpr int kMaxBoardPngSidePx = 24000;

struct BoardArgs {
    tracking::BoardLayout layout;
    std::string output;
    std::string json;
    double dpi = 300;
    bool force = false;
};

const CommandRegistrar reg("board", [](CLI::App& parent) {
    auto* cmd = parent.add_subcommand(
        "board", "Write a printable AprilTag board (PDF or PNG) and its board file (.json)");
    auto a = std::make_shared<BoardArgs>();
    using namespace tracking;
    cmd->add_option("--rows", a->layout.rows, "Tag rows")
        ->capture_default_str()
        ->check(wholeIn(1, kBoardMaxTagsPerSide));
    cmd->add_option("--cols", a->layout.cols, "Tag columns")
        ->capture_default_str()
        ->check(wholeIn(1, kBoardMaxTagsPerSide));
    cmd->add_option("--tag-size", a->layout.tagSize,
                    "Metres between a tag's detection corners (outer black border)")
        ->capture_default_str()
        ->check(finiteIn(kBoardTagSizeM));
    cmd->add_option("--gap", a->layout.gap, "Metres between neighbouring tags")
        ->capture_default_str()
        ->check(finiteIn(kBoardGapM));
    cmd->add_option("--first-id", a->layout.firstId,
                    "Id of the top-left tag (row-major; the family's ids bound it)")
        ->capture_default_str()
        ->check(wholeIn(0, 1 << 20));
    cmd->add_option("--margin", a->layout.margin, "Metres of white around the grid")
        ->capture_default_str()
        ->check(finiteIn(kBoardMarginM));
    cmd->add_option("--family", a->layout.family, "AprilTag family")->capture_default_str();
    cmd->add_option("-o,--output", a->output, "board.pdf (vector) or board.png")
        ->required()
        ->check(outputPath(OutputShape::File));
    cmd->add_option("--json", a->json, "Board file to write (default: output with .json)")
        ->check(outputPath(OutputShape::File));
    cmd->add_option("--dpi", a->dpi, "PNG resolution in dots per inch")
        ->capture_default_str()
        ->check(finiteIn(1, 4800));
    cmd->add_flag("--force", a->force, "Replace an existing board file beside the output");
    cmd->callback([a] {
        const std::filesystem::path out(a->output);
        const tracking::Board board = a->layout.makeBoard();
        std::string ext = out.extension().string();
        for (auto& ch : ext) ch = char(std::tolower(ch));
        if (ext != ".pdf" && ext != ".png")
            throw Error("mirage board: output '" + a->output + "' must end in .pdf or .png");
        std::filesystem::path json = a->json.empty()
                                         ? std::filesystem::path(out).replace_extension(".json")
                                         : std::filesystem::path(a->json);
        // Checked before writing anything (core/OutputFile.h); the board file beside the sheet
        // is not replaced without --force unless named with --json.
        const OutputRule rule{{}, a->force, "mirage board"};
        OutputFile sheetOut(out, OutputOrigin::Named, rule);
        OutputFile jsonOut(json, a->json.empty() ? OutputOrigin::Derived : OutputOrigin::Named,
                           rule);
        // A PNG's pixels: the sheet in inches times the resolution, per side.
        const double maxSidePx =
            std::max(board.sheet->width, board.sheet->height) / 0.0254 * a->dpi;
        if (ext == ".png" && maxSidePx > kMaxBoardPngSidePx)
            throw Error(fmt::format(
                "mirage board: the sheet at {} dpi is {:.0f} pixels wide; at most {} are written "
                "(lower --dpi, or write a .pdf)",
                a->dpi, maxSidePx, kMaxBoardPngSidePx));
        if (ext == ".pdf")
            tracking::writeBoardPdf(sheetOut.temp(), board);
        else
            tracking::writeBoardPng(sheetOut.temp(), board, a->dpi);
        board.save(jsonOut.temp());
        sheetOut.commit();
        jsonOut.commit();
        spdlog::info("wrote {} ({:.1f} x {:.1f} mm, print at 100 %) and {}", out.string(),
                     board.sheet->width * 1000, board.sheet->height * 1000, json.string());
    });
});

}  // namespace
}  // namespace mirage::app

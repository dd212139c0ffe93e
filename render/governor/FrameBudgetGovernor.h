#pragma once
// A frame-time budget for the real-time renderer: before each frame the governor says which
// quality setting to render with (the governed knobs, render/governor/GovernedKnobs.h), after it
// is told how long the frame took. It chooses from the Pareto front of a measured
// speed-vs-error table (SpeedErrorTable: settings no other setting beats in both time and error),
// the most accurate setting predicted to fit the budget.
//
// Prediction: the table's times are of the machine, load and scene it was measured on, so the
// governor keeps one scale, an exponential average of measured / table time of the settings it
// ran, and predicts setting j at scale x table ms of j. A scene whose cost changes (an object
// comes into view, the machine gets busy) moves the scale within a few frames.
//
// Hysteresis, so quality does not flicker: it steps down as soon as `overBudgetFrames`
// consecutive frames ran over the budget (or one ran over by more than half again), to the best
// setting predicted to fit; it steps up only after `underBudgetFrames` consecutive frames in which
// a better setting was predicted to fit with `headroom` to spare, and never straight back to a
// setting it left for running over the budget until the scale has fallen by that headroom.
#include <string>
#include <vector>

#include "render/governor/SpeedErrorTable.h"

namespace mirage::render {

struct GovernorOptions {
    double budgetMs = 33.3;        // the frame time to hold (ms), e.g. the camera's frame interval
    double headroom = 0.15;        // a better setting must fit within (1 - headroom) x budget
    int overBudgetFrames = 2;      // consecutive frames over the budget before stepping down
    int underBudgetFrames = 6;     // consecutive frames with room before stepping up
    double scaleSmoothing = 0.35;  // weight of the newest frame in the scale's average
    // Frames not judged at the start: the first frame also compiles shaders and builds the
    // impostors (several times a frame's cost).
    int warmUpFrames = 1;

    // Throws mirage::Error naming the first value out of range.
    void validate() const;
};

// What the governor holds at `budgetMs` when the table's times are this machine's (its steady
// state at scale 1): the most accurate row of the table's Pareto front within the budget (the
// fastest when none is), beside the most accurate row of all, as a markdown section with the
// front (`mirage bench --budget-ms`: its own rows are the table).
struct BudgetChoice {
    SpeedErrorRow chosen, mostAccurate;
    bool fits = false;  // chosen.frameMs <= the budget
};
BudgetChoice chooseWithinBudget(const SpeedErrorTable& table, double budgetMs);
std::string budgetReport(const SpeedErrorTable& table, double budgetMs);
// The same as a picture (SVG, frame time against PSNR): every row of the table as a point, the
// Pareto front as the step line the governor's choice follows as the budget grows (at any
// budget it holds the front's most accurate setting within it), the setting it holds at this
// budget ringed, and `footagePsnrDb` (the footage alone; NaN: none) as a dashed baseline. Points
// are labelled by the knobs whose values differ between rows.
std::string budgetPlotSvg(const SpeedErrorTable& table, double budgetMs, double footagePsnrDb);

class FrameBudgetGovernor {
public:
    // Starts at the most accurate setting of the table (whose scale is then learned). Throws
    // mirage::Error for an empty table.
    FrameBudgetGovernor(const SpeedErrorTable& table, GovernorOptions options);

    // The setting to render the next frame with.
    const QualitySetting& setting() const { return ladder_[level_].setting; }
    // Index into ladder() (0: fastest, least accurate).
    int level() const { return level_; }
    const std::vector<SpeedErrorRow>& ladder() const { return ladder_; }
    const GovernorOptions& options() const { return options_; }

    // The frame rendered with setting() took `frameMs`; may choose another setting for the next.
    // Returns true when the setting changed.
    bool observe(double frameMs);

    // Predicted frame time (ms) of ladder()[j] at the current scale.
    double predictedMs(int j) const { return scale_ * ladder_[j].frameMs; }
    double scale() const { return scale_; }
    // Settings changes so far.
    int changes() const { return changes_; }
    // Why the current setting was chosen (one line).
    const std::string& reason() const { return reason_; }
    // "quality 3/5: specular_resolution=half ... (table 120 ms, 27.0 dB); predicted 31.0 ms of
    // 33.3 ms: REASON" for the HUD and the log.
    std::string summary() const;

private:
    // The most accurate ladder index predicted to fit `limitMs` (0 when none does).
    int bestFitting(double limitMs) const;
    void moveTo(int level, std::string reason);

    GovernorOptions options_;
    std::vector<SpeedErrorRow> ladder_;  // the table's Pareto front, fastest first
    int level_ = 0;
    double scale_ = 1.0;
    bool scaleKnown_ = false;
    int overRun_ = 0, underRun_ = 0;
    int leftForOverrun_ = -1;     // the level last left for running over the budget
    double scaleWhenLeft_ = 0.0;  // the scale then
    int changes_ = 0;
    int observed_ = 0;
    std::string reason_;
};

}  // namespace mirage::render

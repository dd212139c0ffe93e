#include "render/governor/FrameBudgetGovernor.h"

#include <algorithm>
#include <cmath>
#include <set>

#include <fmt/format.h>

#include "core/Error.h"
#include "core/plot/SvgPlot.h"

namespace mirage::render {

void GovernorOptions::validate() const {
    auto check = [](bool ok, const char* name, const char* range, double v) {
        if (!ok)
            throw Error(fmt::format("frame-time governor: {} must be {}, got {}", name, range, v));
    };
    check(std::isfinite(budgetMs) && budgetMs > 0.0 && budgetMs <= 60000.0, "the budget",
          "in (0, 60000] ms", budgetMs);
    check(headroom >= 0.0 && headroom < 1.0, "headroom", "in [0, 1)", headroom);
    check(overBudgetFrames >= 1 && overBudgetFrames <= 100, "overBudgetFrames", "1..100",
          overBudgetFrames);
    check(underBudgetFrames >= 1 && underBudgetFrames <= 1000, "underBudgetFrames", "1..1000",
          underBudgetFrames);
    check(warmUpFrames >= 0 && warmUpFrames <= 1000, "warmUpFrames", "0..1000", warmUpFrames);
    check(scaleSmoothing > 0.0 && scaleSmoothing <= 1.0, "scaleSmoothing", "in (0, 1]",
          scaleSmoothing);
}

FrameBudgetGovernor::FrameBudgetGovernor(const SpeedErrorTable& table, GovernorOptions options)
    : options_(options), ladder_(table.paretoFront()) {
    options_.validate();
    if (ladder_.empty())
        throw Error(
            "frame-time governor: the speed-vs-error table has no row with a time and an "
            "error (measure one with `mirage bench`)");
    level_ = int(ladder_.size()) - 1;
    reason_ = "start at the most accurate setting, to measure this machine's speed";
}

int FrameBudgetGovernor::bestFitting(double limitMs) const {
    for (int j = int(ladder_.size()) - 1; j > 0; --j)
        if (predictedMs(j) <= limitMs) return j;
    return 0;
}

void FrameBudgetGovernor::moveTo(int level, std::string reason) {
    if (level != level_) ++changes_;
    level_ = level;
    reason_ = std::move(reason);
    overRun_ = 0;
    underRun_ = 0;
}

bool FrameBudgetGovernor::observe(double frameMs) {
    if (!std::isfinite(frameMs) || frameMs <= 0.0) return false;  // nothing measured
    if (observed_++ < options_.warmUpFrames) return false;
    const double budget = options_.budgetMs;
    const double ratio = frameMs / std::max(ladder_[level_].frameMs, 1e-6);
    scale_ = scaleKnown_
                 ? (1.0 - options_.scaleSmoothing) * scale_ + options_.scaleSmoothing * ratio
                 : ratio;
    scaleKnown_ = true;
    const int before = level_;
    if (frameMs > budget) {
        ++overRun_;
        underRun_ = 0;
        // A frame far over the budget (an object came into view) does not wait for a second one.
        if (level_ > 0 && (overRun_ >= options_.overBudgetFrames || frameMs > 1.5 * budget)) {
            // The scale follows the newest frame at once here: the average lags a sudden change.
            scale_ = std::max(scale_, ratio);
            const int to = std::min(bestFitting(budget), level_ - 1);
            leftForOverrun_ = level_;
            scaleWhenLeft_ = scale_;
            moveTo(to, fmt::format("{} frame(s) over the budget ({:.1f} ms > {:.1f} ms); {}",
                                   overRun_, frameMs, budget,
                                   predictedMs(to) <= budget
                                       ? fmt::format("this setting is predicted at {:.1f} ms",
                                                     predictedMs(to))
                                       : std::string("even the fastest setting is predicted "
                                                     "over it")));
        }
        return level_ != before;
    }
    overRun_ = 0;
    const double roomy = (1.0 - options_.headroom) * budget;
    int up = bestFitting(roomy);
    // Back to a setting left for running over the budget only once the frame got cheaper.
    if (leftForOverrun_ >= 0 && up >= leftForOverrun_ &&
        scale_ > (1.0 - options_.headroom) * scaleWhenLeft_)
        up = leftForOverrun_ - 1;
    if (up > level_ && predictedMs(up) <= roomy) {
        if (++underRun_ >= options_.underBudgetFrames) {
            moveTo(up, fmt::format("{} frames with room: predicted {:.1f} ms <= {:.0f} % of the "
                                   "{:.1f} ms budget",
                                   options_.underBudgetFrames, predictedMs(up),
                                   100.0 * (1.0 - options_.headroom), budget));
            if (leftForOverrun_ >= 0 && level_ >= leftForOverrun_) leftForOverrun_ = -1;
        }
    } else {
        underRun_ = 0;
        if (level_ == before && reason_.rfind("start", 0) == 0)
            reason_ = level_ == int(ladder_.size()) - 1
                          ? fmt::format("the most accurate setting fits ({:.1f} ms <= {:.1f} ms)",
                                        frameMs, budget)
                          : reason_;
    }
    return level_ != before;
}

BudgetChoice chooseWithinBudget(const SpeedErrorTable& table, double budgetMs) {
    GovernorOptions o;
    o.budgetMs = budgetMs;
    const FrameBudgetGovernor g(table, o);  // scale 1: the table's own times
    BudgetChoice c;
    const std::vector<SpeedErrorRow>& ladder = g.ladder();
    c.mostAccurate = ladder.back();
    c.chosen = ladder.front();
    for (const SpeedErrorRow& r : ladder)
        if (r.frameMs <= budgetMs) c.chosen = r;
    c.fits = c.chosen.frameMs <= budgetMs;
    return c;
}

std::string budgetReport(const SpeedErrorTable& table, double budgetMs) {
    const BudgetChoice c = chooseWithinBudget(table, budgetMs);
    std::string s = fmt::format(
        "## Frame-time budget {:.1f} ms\n\n"
        "Chosen: **{}**, {:.1f} ms, {:.2f} dB over the influenced pixels{}; the most accurate "
        "setting, {}, {:.1f} ms, {:.2f} dB: **{:+.2f} dB** at the budget.\n\n"
        "The speed-vs-error front the governor chooses from (settings no other beats in both):\n\n"
        "| setting | ms | PSNR infl. dB |\n|---|---:|---:|\n",
        budgetMs, describeQualitySetting(c.chosen.setting), c.chosen.frameMs, c.chosen.psnrDb,
        c.fits ? "" : " (over the budget: the fastest setting)",
        describeQualitySetting(c.mostAccurate.setting), c.mostAccurate.frameMs,
        c.mostAccurate.psnrDb, c.chosen.psnrDb - c.mostAccurate.psnrDb);
    for (const SpeedErrorRow& r : table.paretoFront())
        s += fmt::format("| {} | {:.1f} | {:.2f} |\n", describeQualitySetting(r.setting), r.frameMs,
                         r.psnrDb);
    return s;
}

std::string budgetPlotSvg(const SpeedErrorTable& table, double budgetMs, double footagePsnrDb) {
    const BudgetChoice c = chooseWithinBudget(table, budgetMs);
    const std::vector<SpeedErrorRow>& rows = table.rows();
    std::set<std::string> varying;  // knobs whose value is not the same in every row
    for (const SpeedErrorRow& r : rows)
        for (const auto& [name, value] : r.setting) {
            const auto it = rows.front().setting.find(name);
            if (it == rows.front().setting.end() || it->second != value) varying.insert(name);
        }
    plot::ScatterPlot p;
    p.title =
        fmt::format("Speed against error; ringed: the governor's choice at {:.1f} ms", budgetMs);
    p.xLabel = "ms per frame (median wall)";
    p.yLabel = "PSNR over influenced pixels (dB)";
    for (const SpeedErrorRow& r : rows) {
        std::string label;
        for (const std::string& name : varying) {
            const auto it = r.setting.find(name);
            if (it != r.setting.end())
                label += (label.empty() ? "" : " ") + name + "=" + it->second;
        }
        const bool chosen = r.setting == c.chosen.setting && r.frameMs == c.chosen.frameMs;
        p.points.push_back({r.frameMs, r.psnrDb, label, chosen, false});
    }
    p.hasBaseline = std::isfinite(footagePsnrDb);
    p.baselineY = footagePsnrDb;
    p.baselineLabel = "footage only";
    return plot::svgScatter(p);
}

std::string FrameBudgetGovernor::summary() const {
    const SpeedErrorRow& r = ladder_[level_];
    return fmt::format(
        "quality {}/{}: {} (table {:.1f} ms, {:.2f} dB); predicted {:.1f} ms of "
        "{:.1f} ms: {}",
        level_ + 1, ladder_.size(), describeQualitySetting(r.setting), r.frameMs, r.psnrDb,
        predictedMs(level_), options_.budgetMs, reason_);
}

}  // namespace mirage::render

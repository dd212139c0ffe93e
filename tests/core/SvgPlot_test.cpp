// The results page's plots (core/plot/SvgPlot.h): the Pareto front, the ticks, and that each
// plot holds one element per data item and well-formed text.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "core/plot/SvgPlot.h"

namespace mirage::plot {
namespace {

int count(const std::string& s, const std::string& what) {
    int n = 0;
    for (size_t p = s.find(what); p != std::string::npos; p = s.find(what, p + 1)) ++n;
    return n;
}

TEST(SvgPlot, ParetoFrontKeepsOnlyUndominatedPoints) {
    // (ms, dB): b is faster and better than a; d is slower and worse than c; e ties c in time
    // but is worse; f is not finite.
    const std::vector<Point> pts = {
        {10, 30, "a"}, {8, 31, "b"},  {20, 35, "c"},
        {25, 34, "d"}, {20, 33, "e"}, {std::numeric_limits<double>::quiet_NaN(), 50, "f"},
        {40, 36, "g"}};
    const std::vector<size_t> front = paretoFront(pts);
    ASSERT_EQ(front.size(), 3u);
    EXPECT_EQ(pts[front[0]].label, "b");
    EXPECT_EQ(pts[front[1]].label, "c");
    EXPECT_EQ(pts[front[2]].label, "g");
}

TEST(SvgPlot, ParetoFrontOfEqualPointsKeepsTheFirst) {
    const std::vector<Point> pts = {{5, 20, "first"}, {5, 20, "second"}};
    const std::vector<size_t> front = paretoFront(pts);
    ASSERT_EQ(front.size(), 1u);
    EXPECT_EQ(front[0], 0u);
}

TEST(SvgPlot, TicksAreRoundAndCoverTheRange) {
    const std::vector<double> t = niceTicks(0.0, 173.0);
    ASSERT_GE(t.size(), 4u);
    EXPECT_DOUBLE_EQ(t.front(), 0.0);
    const double step = t[1] - t[0];
    EXPECT_TRUE(step == 20.0 || step == 50.0 || step == 25.0 || step == 40.0) << step;
    EXPECT_LE(t.back(), 173.0);
    EXPECT_GT(t.back() + step, 173.0);
    const std::vector<double> small = niceTicks(21.3, 22.1);
    ASSERT_GE(small.size(), 3u);
    for (double v : small) EXPECT_NEAR(v * 10, std::round(v * 10), 1e-9) << v;
}

TEST(SvgPlot, ScatterDrawsEveryPointTheDefaultAndTheFront) {
    ScatterPlot p;
    p.title = "glass <sphere> & mirror";
    p.xLabel = "ms per frame";
    p.yLabel = "PSNR (dB)";
    p.points = {{10, 30, "vpls=64"}, {20, 32, "vpls=256", true}, {30, 31, "vpls=1024"}};
    p.points[2].flagged = true;
    p.hasBaseline = true;
    p.baselineY = 28;
    p.baselineLabel = "footage only";
    const std::string svg = svgScatter(p);
    EXPECT_EQ(svg.rfind("<svg", 0), 0u);
    EXPECT_NE(svg.find("</svg>"), std::string::npos);
    EXPECT_EQ(count(svg, "class=\"point\""), 3);
    EXPECT_EQ(count(svg, "class=\"default\""), 1);
    EXPECT_EQ(count(svg, "class=\"pareto\""), 1);
    EXPECT_EQ(count(svg, "#D00000"), 2);  // the flagged point and its label
    EXPECT_NE(svg.find("glass &lt;sphere&gt; &amp; mirror"), std::string::npos);
    EXPECT_EQ(svg.find("<sphere>"), std::string::npos);
    EXPECT_EQ(svg.find("nan"), std::string::npos);
}

TEST(SvgPlot, StackedBarsHaveOneSegmentPerPositiveValue) {
    StackedBarPlot p;
    p.title = "per pass";
    p.bars = {{"diffuse", {{"gbuffer", 5}, {"direct", 3}, {"indirect", 0}}},
              {"glass", {{"gbuffer", 6}, {"specgbuf", 20}}}};
    const std::string svg = svgStackedBars(p);
    EXPECT_EQ(count(svg, "class=\"segment\""), 4);
    EXPECT_NE(svg.find(">diffuse<"), std::string::npos);
    EXPECT_NE(svg.find(">26<"), std::string::npos);  // the glass bar's total
}

TEST(SvgPlot, LinesDropNonPositiveValuesOnLogAxes) {
    LinePlot p;
    p.logX = true;
    p.series = {{"frame", {{0, 5, ""}, {100, 10, ""}, {1000, 20, ""}}}};
    const std::string svg = svgLines(p);
    EXPECT_EQ(count(svg, "<circle"), 2);
    EXPECT_EQ(svg.find("inf"), std::string::npos);
}

}  // namespace
}  // namespace mirage::plot

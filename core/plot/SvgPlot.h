#pragma once
// Plots as SVG text, written by the project so that the results page (`mirage bench --suite`,
// docs/results.md) needs nothing but the mirage binary: no Python, no plotting package. SVG
// because it is text (diffable, small, viewed by every browser and by GitHub's markdown), and
// three kinds of plot are all the page needs: speed against error (points, their Pareto front, a
// marked default and a horizontal baseline), stacked bars (time per pass) and lines (scaling).
//
// Coordinates are data units; the axes are linear (or log10 where asked) with ticks at 1, 2, 5 x
// 10^k. Every function returns the whole document (<svg ...>...</svg>).
#include <string>
#include <vector>

namespace mirage::plot {

struct Point {
    double x = 0.0, y = 0.0;
    std::string label;     // shown beside the point (short: "vpls=64")
    bool marked = false;   // the default configuration: drawn as a ring around the dot
    bool flagged = false;  // drawn in red (e.g. a configuration that does not beat the baseline)
};

// Indices of the points on the Pareto front of "smaller x is better, larger y is better" (for
// speed against error: ms per frame against PSNR), sorted by x. A point is on the front when no
// other point has x <= its x and y >= its y with one of them strict. Non-finite points are never
// on it. Equal points: the first is kept.
std::vector<size_t> paretoFront(const std::vector<Point>& points);

// Tick positions covering [lo, hi] at 1, 2 or 5 x 10^k, about `target` of them (at least 2).
std::vector<double> niceTicks(double lo, double hi, int target = 6);

struct ScatterPlot {
    std::string title, xLabel, yLabel;
    std::vector<Point> points;
    bool drawFront = true;     // the Pareto front as a step line
    bool hasBaseline = false;  // a horizontal dashed line at baselineY
    double baselineY = 0.0;
    std::string baselineLabel;      // e.g. "footage only"
    int width = 640, height = 420;  // SVG size (px)
};
std::string svgScatter(const ScatterPlot& plot);

struct BarSegment {
    std::string name;  // legend entry (same name = same colour across bars)
    double value = 0.0;
};
struct Bar {
    std::string label;  // left of the bar
    std::vector<BarSegment> segments;
};
// Horizontal stacked bars, one per entry, segments left to right in order; the total is written
// at each bar's end.
struct StackedBarPlot {
    std::string title, xLabel;
    std::vector<Bar> bars;
    int width = 720;  // the height follows the number of bars and legend entries
};
std::string svgStackedBars(const StackedBarPlot& plot);

struct Series {
    std::string name;
    std::vector<Point> points;  // joined in order
};
struct LinePlot {
    std::string title, xLabel, yLabel;
    std::vector<Series> series;
    bool logX = false, logY = false;  // log10 axes (non-positive values are dropped)
    int width = 640, height = 420;
};
std::string svgLines(const LinePlot& plot);

// Escapes &, <, >, " for SVG/XML text and attributes.
std::string xmlEscape(const std::string& text);

}  // namespace mirage::plot

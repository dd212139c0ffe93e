#include "core/plot/SvgPlot.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include <fmt/format.h>

namespace mirage::plot {
namespace {

// Colour-blind-safe palette (Okabe and Ito 2008), cycled.
const char* const kPalette[] = {"#0072B2", "#E69F00", "#009E73", "#CC79A7", "#56B4E9",
                                "#D55E00", "#F0E442", "#000000", "#999999"};
constexpr int kPaletteSize = sizeof kPalette / sizeof kPalette[0];
const char* const kFlagColour = "#D00000";

// Plot area inside the SVG, in pixels.
struct Frame {
    double left = 72, right = 24, top = 40, bottom = 52;
    double width = 0, height = 0;  // of the whole SVG
    double x0() const { return left; }
    double x1() const { return width - right; }
    double y0() const { return height - bottom; }  // bottom of the plot area
    double y1() const { return top; }
};

// A linear or log10 axis mapping data values onto [p0, p1] pixels.
struct Axis {
    double lo = 0, hi = 1;
    bool log = false;
    double p0 = 0, p1 = 1;
    double t(double v) const { return log ? std::log10(v) : v; }
    double map(double v) const {
        const double a = t(lo), b = t(hi);
        return p0 + (t(v) - a) / (b - a) * (p1 - p0);
    }
};

std::string fmtNum(double v) {
    if (v == 0) return "0";
    const double a = std::abs(v);
    if (a >= 1e5 || a < 1e-3) return fmt::format("{:.3g}", v);
    if (a >= 100) return fmt::format("{:.0f}", v);
    if (a >= 10) return fmt::format("{:.3g}", v);
    return fmt::format("{:.3g}", v);
}

// Range [lo, hi] of the values with a margin, never empty.
void padRange(double& lo, double& hi, bool log) {
    if (!(lo <= hi)) lo = 0, hi = 1;
    if (log) {
        if (hi <= lo * 1.0001) lo /= 2, hi *= 2;
        lo /= 1.15, hi *= 1.15;
        return;
    }
    if (hi - lo < 1e-12 * std::max(1.0, std::abs(hi))) {
        const double d = std::max(std::abs(hi) * 0.1, 1.0);
        lo -= d, hi += d;
        return;
    }
    const double m = (hi - lo) * 0.08;
    lo -= m, hi += m;
}

std::vector<double> logTicks(double lo, double hi) {
    std::vector<double> t;
    for (int e = int(std::floor(std::log10(lo))); e <= int(std::ceil(std::log10(hi))); ++e)
        for (double m : {1.0, 2.0, 5.0}) {
            const double v = m * std::pow(10.0, e);
            if (v >= lo && v <= hi) t.push_back(v);
        }
    if (t.size() < 2) return niceTicks(lo, hi);
    return t;
}

std::string header(double w, double h) {
    return fmt::format(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{0:.0f}\" height=\"{1:.0f}\" "
        "viewBox=\"0 0 {0:.0f} {1:.0f}\" font-family=\"sans-serif\" font-size=\"12\">\n"
        "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n",
        w, h);
}

std::string text(double x, double y, const std::string& s, const char* anchor = "start",
                 int size = 12, const std::string& extra = {}) {
    return fmt::format(
        "<text x=\"{:.1f}\" y=\"{:.1f}\" text-anchor=\"{}\" font-size=\"{}\"{}>{}</text>\n", x, y,
        anchor, size, extra, xmlEscape(s));
}

// Axes, grid, ticks and labels of a plot area.
std::string axes(const Frame& f, const Axis& ax, const Axis& ay, const std::string& title,
                 const std::string& xLabel, const std::string& yLabel) {
    std::string s;
    s += text(f.width / 2, 22, title, "middle", 15, " font-weight=\"bold\"");
    const std::vector<double> xt = ax.log ? logTicks(ax.lo, ax.hi) : niceTicks(ax.lo, ax.hi);
    const std::vector<double> yt = ay.log ? logTicks(ay.lo, ay.hi) : niceTicks(ay.lo, ay.hi);
    for (double v : xt) {
        const double x = ax.map(v);
        if (x < f.x0() - 0.5 || x > f.x1() + 0.5) continue;
        s += fmt::format(
            "<line x1=\"{0:.1f}\" y1=\"{1:.1f}\" x2=\"{0:.1f}\" y2=\"{2:.1f}\" "
            "stroke=\"#e4e4e4\"/>\n",
            x, f.y1(), f.y0());
        s += text(x, f.y0() + 16, fmtNum(v), "middle");
    }
    for (double v : yt) {
        const double y = ay.map(v);
        if (y > f.y0() + 0.5 || y < f.y1() - 0.5) continue;
        s += fmt::format(
            "<line x1=\"{0:.1f}\" y1=\"{1:.1f}\" x2=\"{2:.1f}\" y2=\"{1:.1f}\" "
            "stroke=\"#e4e4e4\"/>\n",
            f.x0(), y, f.x1());
        s += text(f.x0() - 6, y + 4, fmtNum(v), "end");
    }
    s += fmt::format(
        "<rect x=\"{:.1f}\" y=\"{:.1f}\" width=\"{:.1f}\" height=\"{:.1f}\" fill=\"none\" "
        "stroke=\"#444\"/>\n",
        f.x0(), f.y1(), f.x1() - f.x0(), f.y0() - f.y1());
    s += text((f.x0() + f.x1()) / 2, f.height - 12, xLabel, "middle");
    s += fmt::format(
        "<text x=\"16\" y=\"{0:.1f}\" text-anchor=\"middle\" transform=\"rotate(-90 16 "
        "{0:.1f})\">{1}"
        "</text>\n",
        (f.y0() + f.y1()) / 2, xmlEscape(yLabel));
    return s;
}

bool finite(const Point& p) {
    return std::isfinite(p.x) && std::isfinite(p.y);
}

}  // namespace

std::string xmlEscape(const std::string& text) {
    std::string s;
    s.reserve(text.size());
    for (char c : text) switch (c) {
            case '&':
                s += "&amp;";
                break;
            case '<':
                s += "&lt;";
                break;
            case '>':
                s += "&gt;";
                break;
            case '"':
                s += "&quot;";
                break;
            default:
                s += c;
        }
    return s;
}

std::vector<size_t> paretoFront(const std::vector<Point>& points) {
    std::vector<size_t> order;
    for (size_t i = 0; i < points.size(); ++i)
        if (finite(points[i])) order.push_back(i);
    // By x ascending, then y descending, then input order: a sweep keeps each point whose y beats
    // every point before it (all of which are at least as fast).
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
        if (points[a].x != points[b].x) return points[a].x < points[b].x;
        return points[a].y > points[b].y;
    });
    std::vector<size_t> front;
    double best = -std::numeric_limits<double>::infinity();
    for (size_t i : order)
        if (points[i].y > best) {
            front.push_back(i);
            best = points[i].y;
        }
    return front;
}

std::vector<double> niceTicks(double lo, double hi, int target) {
    if (!(std::isfinite(lo) && std::isfinite(hi))) return {};
    if (hi < lo) std::swap(lo, hi);
    if (hi - lo <= 0) return {lo};
    target = std::max(target, 2);
    const double raw = (hi - lo) / target;
    const double mag = std::pow(10.0, std::floor(std::log10(raw)));
    double step = mag;
    for (double m : {1.0, 2.0, 5.0, 10.0})
        if (m * mag >= raw) {
            step = m * mag;
            break;
        }
    std::vector<double> t;
    for (double v = std::ceil(lo / step) * step; v <= hi + step * 1e-9; v += step)
        t.push_back(std::abs(v) < step * 1e-9 ? 0.0 : v);
    return t;
}

std::string svgScatter(const ScatterPlot& p) {
    Frame f;
    f.width = p.width;
    f.height = p.height;
    double xlo = std::numeric_limits<double>::infinity(), xhi = -xlo, ylo = xlo, yhi = -xlo;
    for (const Point& q : p.points)
        if (finite(q)) {
            xlo = std::min(xlo, q.x), xhi = std::max(xhi, q.x);
            ylo = std::min(ylo, q.y), yhi = std::max(yhi, q.y);
        }
    if (p.hasBaseline && std::isfinite(p.baselineY))
        ylo = std::min(ylo, p.baselineY), yhi = std::max(yhi, p.baselineY);
    if (!std::isfinite(xlo)) xlo = 0, xhi = 1;
    if (!std::isfinite(ylo)) ylo = 0, yhi = 1;
    xlo = std::min(xlo, 0.0);  // time axes start at 0: ratios read off the plot
    padRange(xlo, xhi, false);
    xlo = std::max(xlo, 0.0);
    padRange(ylo, yhi, false);
    const Axis ax{xlo, xhi, false, f.x0(), f.x1()};
    const Axis ay{ylo, yhi, false, f.y0(), f.y1()};
    std::string s = header(f.width, f.height);
    s += axes(f, ax, ay, p.title, p.xLabel, p.yLabel);
    if (p.hasBaseline && std::isfinite(p.baselineY)) {
        const double y = ay.map(p.baselineY);
        s += fmt::format(
            "<line x1=\"{:.1f}\" y1=\"{:.1f}\" x2=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"#888\" "
            "stroke-dasharray=\"6 4\"/>\n",
            f.x0(), y, f.x1(), y);
        s += text(f.x0() + 6, y - 5, p.baselineLabel, "start", 11, " fill=\"#666\"");
    }
    if (p.drawFront) {
        const std::vector<size_t> front = paretoFront(p.points);
        if (front.size() > 1) {
            std::string d;
            for (size_t k = 0; k < front.size(); ++k) {
                const Point& q = p.points[front[k]];
                if (k == 0)
                    d += fmt::format("M{:.1f},{:.1f}", ax.map(q.x), ay.map(q.y));
                else  // step: at the faster point's quality until the slower point's time
                    d += fmt::format(" H{:.1f} V{:.1f}", ax.map(q.x), ay.map(q.y));
            }
            s += fmt::format(
                "<path class=\"pareto\" d=\"{}\" fill=\"none\" stroke=\"{}\" "
                "stroke-width=\"1.5\"/>\n",
                d, kPalette[1]);
        }
    }
    // Labels are placed greedily: beside the point, else above or below it at growing distance,
    // where they overlap no label placed before (settings that tie in error sit on one line).
    struct Box {
        double x0, y0, x1, y1;
    };
    std::vector<Box> placed;
    const auto freeAt = [&](const Box& b) {
        for (const Box& o : placed)
            if (b.x0 < o.x1 && o.x0 < b.x1 && b.y0 < o.y1 && o.y0 < b.y1) return false;
        return true;
    };
    for (const Point& q : p.points) {
        if (!finite(q)) continue;
        const double x = ax.map(q.x), y = ay.map(q.y);
        if (q.label.empty()) continue;
        const double w = 5.6 * double(q.label.size()), h = 11;
        // Right of the point, or left when it would leave the plot.
        const double lx = x + 7 + w > f.x1() ? x - 7 - w : x + 7;
        Box best{lx, y - 6 - h, lx + w, y - 6};
        for (int k = 0; k < 12; ++k) {
            const double dy = (k % 2 == 0 ? -1.0 : 1.0) * double((k + 1) / 2) * (h + 1);
            const Box b{lx, y - 6 - h + dy, lx + w, y - 6 + dy};
            if (b.y0 < f.y1() || b.y1 > f.y0()) continue;
            if (freeAt(b)) {
                best = b;
                break;
            }
        }
        placed.push_back(best);
        if (std::abs(best.y1 - (y - 6)) > 1)  // moved away: a leader line to its point
            s += fmt::format(
                "<line x1=\"{:.1f}\" y1=\"{:.1f}\" x2=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"#bbb\"/>\n",
                x, y, best.x0 < x ? best.x1 : best.x0, best.y1 - 4);
        s += text(best.x0, best.y1, q.label, "start", 10, q.flagged ? " fill=\"#D00000\"" : "");
    }
    for (const Point& q : p.points) {
        if (!finite(q)) continue;
        const double x = ax.map(q.x), y = ay.map(q.y);
        const char* colour = q.flagged ? kFlagColour : kPalette[0];
        s += fmt::format(
            "<circle class=\"point\" cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"4\" fill=\"{}\"/>\n", x, y,
            colour);
        if (q.marked)
            s += fmt::format(
                "<circle class=\"default\" cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"8\" fill=\"none\" "
                "stroke=\"#000\" stroke-width=\"1.5\"/>\n",
                x, y);
    }
    s += text(f.x1(), f.y1() - 6,
              "o default    - Pareto front (faster or better than every other point)", "end", 10,
              " fill=\"#555\"");
    s += "</svg>\n";
    return s;
}

std::string svgStackedBars(const StackedBarPlot& p) {
    // Legend order = first appearance; colours by name.
    std::vector<std::string> names;
    for (const Bar& b : p.bars)
        for (const BarSegment& g : b.segments)
            if (std::find(names.begin(), names.end(), g.name) == names.end())
                names.push_back(g.name);
    std::map<std::string, const char*> colour;
    for (size_t i = 0; i < names.size(); ++i) colour[names[i]] = kPalette[i % kPaletteSize];
    const double barH = 22, gap = 10, legendRow = 18;
    const int legendCols = 4;
    const int legendRows = int((names.size() + legendCols - 1) / legendCols);
    Frame f;
    f.left = 150;
    f.right = 70;
    f.width = p.width;
    f.bottom = 66 + legendRows * legendRow;
    f.height = f.top + double(p.bars.size()) * (barH + gap) + gap + f.bottom;
    double hi = 0;
    for (const Bar& b : p.bars) {
        double sum = 0;
        for (const BarSegment& g : b.segments) sum += std::max(0.0, g.value);
        hi = std::max(hi, sum);
    }
    if (!(hi > 0)) hi = 1;
    const Axis ax{0, hi * 1.05, false, f.x0(), f.x1()};
    std::string s = header(f.width, f.height);
    s += text(f.width / 2, 22, p.title, "middle", 15, " font-weight=\"bold\"");
    for (double v : niceTicks(0, hi * 1.05)) {
        const double x = ax.map(v);
        s += fmt::format(
            "<line x1=\"{0:.1f}\" y1=\"{1:.1f}\" x2=\"{0:.1f}\" y2=\"{2:.1f}\" "
            "stroke=\"#e4e4e4\"/>\n",
            x, f.y1(), f.y0() + 0);
        s += text(x, f.height - f.bottom + 16, fmtNum(v), "middle");
    }
    double y = f.top + gap;
    for (const Bar& b : p.bars) {
        s += text(f.x0() - 8, y + barH * 0.7, b.label, "end");
        double x = 0;
        for (const BarSegment& g : b.segments) {
            const double v = std::max(0.0, g.value);
            if (!(v > 0) || !std::isfinite(v)) continue;
            s += fmt::format(
                "<rect class=\"segment\" x=\"{:.1f}\" y=\"{:.1f}\" width=\"{:.1f}\" "
                "height=\"{:.1f}\" fill=\"{}\"><title>{}: {}</title></rect>\n",
                ax.map(x), y, ax.map(x + v) - ax.map(x), barH, colour[g.name], xmlEscape(g.name),
                fmtNum(v));
            x += v;
        }
        s += text(ax.map(x) + 6, y + barH * 0.7, fmtNum(x), "start", 11);
        y += barH + gap;
    }
    s += text((f.x0() + f.x1()) / 2, f.height - f.bottom + 34, p.xLabel, "middle");
    const double legendTop = f.height - f.bottom + 62;
    const double colW = (f.width - 40) / legendCols;
    for (size_t i = 0; i < names.size(); ++i) {
        const double lx = 20 + double(i % legendCols) * colW;
        const double ly = legendTop + double(i / legendCols) * legendRow;
        s += fmt::format(
            "<rect x=\"{:.1f}\" y=\"{:.1f}\" width=\"12\" height=\"12\" fill=\"{}\"/>\n", lx,
            ly - 10, colour[names[i]]);
        s += text(lx + 16, ly, names[i], "start", 11);
    }
    s += "</svg>\n";
    return s;
}

std::string svgLines(const LinePlot& p) {
    Frame f;
    f.width = p.width;
    f.height = p.height;
    f.right = 150;  // legend
    double xlo = std::numeric_limits<double>::infinity(), xhi = -xlo, ylo = xlo, yhi = -xlo;
    auto usable = [&](const Point& q) {
        return finite(q) && (!p.logX || q.x > 0) && (!p.logY || q.y > 0);
    };
    for (const Series& se : p.series)
        for (const Point& q : se.points)
            if (usable(q)) {
                xlo = std::min(xlo, q.x), xhi = std::max(xhi, q.x);
                ylo = std::min(ylo, q.y), yhi = std::max(yhi, q.y);
            }
    if (!std::isfinite(xlo)) xlo = 1, xhi = 10;
    if (!std::isfinite(ylo)) ylo = 1, yhi = 10;
    if (!p.logY) ylo = std::min(ylo, 0.0);
    padRange(xlo, xhi, p.logX);
    padRange(ylo, yhi, p.logY);
    if (!p.logY) ylo = std::max(ylo, 0.0);
    const Axis ax{xlo, xhi, p.logX, f.x0(), f.x1()};
    const Axis ay{ylo, yhi, p.logY, f.y0(), f.y1()};
    std::string s = header(f.width, f.height);
    s += axes(f, ax, ay, p.title, p.xLabel, p.yLabel);
    for (size_t k = 0; k < p.series.size(); ++k) {
        const Series& se = p.series[k];
        const char* c = kPalette[k % kPaletteSize];
        std::string d;
        for (const Point& q : se.points) {
            if (!usable(q)) continue;
            d += fmt::format("{}{:.1f},{:.1f}", d.empty() ? "M" : " L", ax.map(q.x), ay.map(q.y));
        }
        if (!d.empty())
            s += fmt::format(
                "<path class=\"series\" d=\"{}\" fill=\"none\" stroke=\"{}\" "
                "stroke-width=\"2\"/>\n",
                d, c);
        for (const Point& q : se.points)
            if (usable(q))
                s += fmt::format("<circle cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"3\" fill=\"{}\"/>\n",
                                 ax.map(q.x), ay.map(q.y), c);
        const double ly = f.y1() + 14 + double(k) * 18;
        s += fmt::format(
            "<line x1=\"{:.1f}\" y1=\"{:.1f}\" x2=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"{}\" "
            "stroke-width=\"2\"/>\n",
            f.x1() + 10, ly - 4, f.x1() + 28, ly - 4, c);
        s += text(f.x1() + 32, ly, se.name, "start", 11);
    }
    s += "</svg>\n";
    return s;
}

}  // namespace mirage::plot

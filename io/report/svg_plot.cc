#include "io/report/svg_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <limits>
#include <sstream>

namespace pvtwin {

namespace {

constexpr double kMarginLeft = 64, kMarginRight = 16, kMarginTop = 28, kMarginBottom = 44;

std::string Num(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", x);
  return buf;
}

// "Nice" tick step for a range: 1, 2 or 5 × 10^k giving about `target` ticks.
double TickStep(double span, int target) {
  if (!(span > 0.0)) return 1.0;
  const double raw = span / target;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  for (double f : {1.0, 2.0, 5.0, 10.0}) {
    if (raw <= f * mag) return f * mag;
  }
  return 10.0 * mag;
}

std::string TickLabel(double v, double step) {
  char buf[32];
  if (step >= 1.0 || v == 0.0) {
    std::snprintf(buf, sizeof buf, "%g", std::round(v / step) * step + 0.0);  // no "-0"
  } else {
    std::snprintf(buf, sizeof buf, "%.*f", static_cast<int>(std::ceil(-std::log10(step))), v);
  }
  return buf;
}

std::string UtcLabel(double t, bool with_hour) {
  const auto tt = static_cast<std::time_t>(t);
  std::tm tm{};
  gmtime_r(&tt, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, with_hour ? "%m-%d %H:%M" : "%m-%d", &tm);
  return buf;
}

struct Frame {
  double x0, x1, y0, y1;            // data ranges
  double left, right, top, bottom;  // pixel box
  double X(double x) const { return left + (x - x0) / (x1 - x0) * (right - left); }
  double Y(double y) const { return bottom - (y - y0) / (y1 - y0) * (bottom - top); }
};

void Axes(std::ostringstream& s, const Frame& f, const std::string& title, const std::string& xl,
          const std::string& yl, bool x_time, double width, double height) {
  s << "<text x='" << Num(width / 2) << "' y='18' text-anchor='middle' font-size='14' "
    << "font-weight='bold'>" << XmlEscape(title) << "</text>\n";
  s << "<rect x='" << Num(f.left) << "' y='" << Num(f.top) << "' width='" << Num(f.right - f.left)
    << "' height='" << Num(f.bottom - f.top) << "' fill='none' stroke='#888'/>\n";
  const double ys = TickStep(f.y1 - f.y0, 5);
  for (double v = std::ceil(f.y0 / ys) * ys; v <= f.y1 + 1e-9 * ys; v += ys) {
    s << "<line x1='" << Num(f.left) << "' x2='" << Num(f.right) << "' y1='" << Num(f.Y(v))
      << "' y2='" << Num(f.Y(v)) << "' stroke='#eee'/>"
      << "<text x='" << Num(f.left - 4) << "' y='" << Num(f.Y(v) + 4)
      << "' text-anchor='end' font-size='11'>" << TickLabel(v, ys) << "</text>\n";
  }
  double xs = TickStep(f.x1 - f.x0, 8);
  if (x_time) {
    xs = (f.x1 - f.x0) > 3 * 86400.0 ? 86400.0 : ((f.x1 - f.x0) > 43200.0 ? 6 * 3600.0 : 3600.0);
    while ((f.x1 - f.x0) / xs > 12) xs *= 2;
  }
  for (double v = std::ceil(f.x0 / xs) * xs; v <= f.x1 + 1e-9 * xs; v += xs) {
    s << "<line y1='" << Num(f.top) << "' y2='" << Num(f.bottom) << "' x1='" << Num(f.X(v))
      << "' x2='" << Num(f.X(v)) << "' stroke='#eee'/>"
      << "<text x='" << Num(f.X(v)) << "' y='" << Num(f.bottom + 14)
      << "' text-anchor='middle' font-size='11'>"
      << (x_time ? UtcLabel(v, xs < 86400.0) : TickLabel(v, xs)) << "</text>\n";
  }
  s << "<text x='" << Num((f.left + f.right) / 2) << "' y='" << Num(height - 6)
    << "' text-anchor='middle' font-size='12'>" << XmlEscape(xl) << "</text>\n";
  s << "<text transform='translate(14," << Num((f.top + f.bottom) / 2)
    << ") rotate(-90)' text-anchor='middle' font-size='12'>" << XmlEscape(yl) << "</text>\n";
  (void)width;
}

// Colour for t in [0, 1]: white → orange → dark red.
std::string HeatColor(double t) {
  t = std::clamp(t, 0.0, 1.0);
  const int r = static_cast<int>(255 - 80 * t);
  const int g = static_cast<int>(245 - 215 * t);
  const int b = static_cast<int>(235 - 225 * t);
  char buf[16];
  std::snprintf(buf, sizeof buf, "#%02x%02x%02x", r, g, b);
  return buf;
}

}  // namespace

std::string XmlEscape(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '\'':
        out += "&#39;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string SvgXYPlot(const std::vector<SvgSeries>& series, const SvgXYOptions& o) {
  double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
  for (const SvgSeries& s : series) {
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      x0 = std::min(x0, s.x[i]);
      x1 = std::max(x1, s.x[i]);
      y0 = std::min(y0, s.y[i]);
      y1 = std::max(y1, s.y[i]);
    }
  }
  if (!(x1 >= x0)) x0 = 0, x1 = 1, y0 = 0, y1 = 1;
  if (o.diagonal) x0 = y0 = std::min(x0, y0), x1 = y1 = std::max(x1, y1);
  if (x1 == x0) x1 = x0 + 1;
  if (y1 == y0) y1 = y0 + 1;
  const double pad = 0.04 * (y1 - y0);
  y0 -= pad;
  y1 += pad;
  Frame f{
      x0, x1, y0, y1, kMarginLeft, o.width - kMarginRight, kMarginTop, o.height - kMarginBottom};
  std::ostringstream s;
  s << "<svg xmlns='http://www.w3.org/2000/svg' width='" << Num(o.width) << "' height='"
    << Num(o.height) << "' font-family='sans-serif'>\n";
  Axes(s, f, o.title, o.x_label, o.y_label, o.x_is_unix_time, o.width, o.height);
  if (o.diagonal) {
    s << "<line x1='" << Num(f.X(x0)) << "' y1='" << Num(f.Y(x0)) << "' x2='" << Num(f.X(x1))
      << "' y2='" << Num(f.Y(x1)) << "' stroke='#999' stroke-dasharray='4 3'/>\n";
  }
  double legend_x = f.left + 8;
  for (const SvgSeries& ser : series) {
    const std::size_t n = std::min(ser.x.size(), ser.y.size());
    const std::size_t stride = std::max<std::size_t>(1, (n + o.max_points - 1) / o.max_points);
    if (ser.points) {
      s << "<g fill='" << ser.color << "' fill-opacity='0.5'>";
      for (std::size_t i = 0; i < n; i += stride) {
        if (!std::isfinite(ser.x[i]) || !std::isfinite(ser.y[i])) continue;
        s << "<circle cx='" << Num(f.X(ser.x[i])) << "' cy='" << Num(f.Y(ser.y[i]))
          << "' r='1.6'/>";
      }
      s << "</g>\n";
    } else {
      std::string path;
      bool pen_down = false;
      double prev_x = std::nan("");
      for (std::size_t i = 0; i < n; i += stride) {
        if (!std::isfinite(ser.x[i]) || !std::isfinite(ser.y[i])) {
          pen_down = false;
          continue;
        }
        // A gap of more than 2 h in time series breaks the line.
        const bool gap = o.x_is_unix_time && std::isfinite(prev_x) && ser.x[i] - prev_x > 7200.0;
        path += (pen_down && !gap ? "L" : "M") + Num(f.X(ser.x[i])) + " " + Num(f.Y(ser.y[i]));
        pen_down = true;
        prev_x = ser.x[i];
      }
      s << "<path d='" << path << "' fill='none' stroke='" << ser.color << "' stroke-width='1'/>\n";
    }
    s << "<rect x='" << Num(legend_x) << "' y='" << Num(f.top + 6)
      << "' width='10' height='10' fill='" << ser.color << "'/><text x='" << Num(legend_x + 14)
      << "' y='" << Num(f.top + 15) << "' font-size='11'>" << XmlEscape(ser.name) << "</text>\n";
    legend_x += 24 + 7.0 * static_cast<double>(ser.name.size());
  }
  s << "</svg>\n";
  return s.str();
}

std::string SvgHeatmapPlot(const SvgHeatmap& m) {
  const std::size_t nx = m.x_edges.size() > 1 ? m.x_edges.size() - 1 : 0;
  const std::size_t ny = m.y_edges.size() > 1 ? m.y_edges.size() - 1 : 0;
  double vmax = 0.0;
  for (double v : m.values) {
    if (std::isfinite(v)) vmax = std::max(vmax, v);
  }
  const double legend_w = 70;
  Frame f{m.x_edges.empty() ? 0 : m.x_edges.front(),
          m.x_edges.empty() ? 1 : m.x_edges.back(),
          m.y_edges.empty() ? 0 : m.y_edges.front(),
          m.y_edges.empty() ? 1 : m.y_edges.back(),
          kMarginLeft,
          m.width - kMarginRight - legend_w,
          kMarginTop,
          m.height - kMarginBottom};
  std::ostringstream s;
  s << "<svg xmlns='http://www.w3.org/2000/svg' width='" << Num(m.width) << "' height='"
    << Num(m.height) << "' font-family='sans-serif'>\n";
  for (std::size_t iy = 0; iy < ny; ++iy) {
    for (std::size_t ix = 0; ix < nx; ++ix) {
      const std::size_t k = iy * nx + ix;
      if (k >= m.values.size() || !std::isfinite(m.values[k])) continue;
      const double xa = f.X(m.x_edges[ix]), xb = f.X(m.x_edges[ix + 1]);
      const double ya = f.Y(m.y_edges[iy + 1]), yb = f.Y(m.y_edges[iy]);
      s << "<rect x='" << Num(xa) << "' y='" << Num(ya) << "' width='" << Num(xb - xa)
        << "' height='" << Num(yb - ya) << "' fill='"
        << HeatColor(vmax > 0 ? m.values[k] / vmax : 0) << "'><title>"
        << TickLabel(m.values[k], 0.01) << "</title></rect>\n";
    }
  }
  Axes(s, f, m.title, m.x_label, m.y_label, false, m.width, m.height);
  // Colour legend.
  const double lx = m.width - kMarginRight - legend_w + 16;
  for (int k = 0; k < 10; ++k) {
    const double y = f.bottom - (k + 1) * (f.bottom - f.top) / 10.0;
    s << "<rect x='" << Num(lx) << "' y='" << Num(y) << "' width='14' height='"
      << Num((f.bottom - f.top) / 10.0) << "' fill='" << HeatColor((k + 0.5) / 10.0) << "'/>";
  }
  s << "<text x='" << Num(lx + 18) << "' y='" << Num(f.top + 8) << "' font-size='11'>"
    << TickLabel(vmax, 0.1) << "</text><text x='" << Num(lx + 18) << "' y='" << Num(f.bottom)
    << "' font-size='11'>0</text><text x='" << Num(lx) << "' y='" << Num(f.bottom + 14)
    << "' font-size='11'>" << XmlEscape(m.value_label) << "</text>\n";
  s << "</svg>\n";
  return s.str();
}

std::string SvgBarPlot(const std::string& title, const std::vector<std::string>& names,
                       const std::vector<std::string>& colors,
                       const std::vector<SvgBarGroup>& groups, double width) {
  const double bar_h = 9, group_gap = 8, label_w = 230;
  const std::size_t nb = names.size();
  const double height =
      kMarginTop + 24 + static_cast<double>(groups.size()) * (nb * bar_h + group_gap) + 24;
  double vmax = 0.0;
  for (const SvgBarGroup& g : groups) {
    for (double v : g.values) {
      if (std::isfinite(v)) vmax = std::max(vmax, v);
    }
  }
  if (!(vmax > 0)) vmax = 1;
  const double left = label_w, right = width - kMarginRight - 40;
  std::ostringstream s;
  s << "<svg xmlns='http://www.w3.org/2000/svg' width='" << Num(width) << "' height='"
    << Num(height) << "' font-family='sans-serif'>\n";
  s << "<text x='" << Num(width / 2) << "' y='18' text-anchor='middle' font-size='14' "
    << "font-weight='bold'>" << XmlEscape(title) << "</text>\n";
  double lx = left;
  for (std::size_t k = 0; k < nb; ++k) {
    s << "<rect x='" << Num(lx) << "' y='" << Num(kMarginTop) << "' width='10' height='10' fill='"
      << colors[k % colors.size()] << "'/><text x='" << Num(lx + 14) << "' y='"
      << Num(kMarginTop + 9) << "' font-size='11'>" << XmlEscape(names[k]) << "</text>";
    lx += 30 + 7.0 * static_cast<double>(names[k].size());
  }
  double y = kMarginTop + 24;
  for (const SvgBarGroup& g : groups) {
    s << "<text x='" << Num(left - 6) << "' y='" << Num(y + nb * bar_h / 2 + 4)
      << "' text-anchor='end' font-size='11'>" << XmlEscape(g.label) << "</text>";
    for (std::size_t k = 0; k < nb && k < g.values.size(); ++k) {
      const double v = std::isfinite(g.values[k]) ? g.values[k] : 0.0;
      s << "<rect x='" << Num(left) << "' y='" << Num(y + k * bar_h) << "' width='"
        << Num((right - left) * v / vmax) << "' height='" << Num(bar_h - 1) << "' fill='"
        << colors[k % colors.size()] << "'/>";
      s << "<text x='" << Num(left + (right - left) * v / vmax + 3) << "' y='"
        << Num(y + k * bar_h + bar_h - 2) << "' font-size='9'>" << TickLabel(v, 0.001) << "</text>";
    }
    s << "\n";
    y += nb * bar_h + group_gap;
  }
  s << "</svg>\n";
  return s.str();
}

}  // namespace pvtwin

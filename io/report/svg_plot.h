// Minimal SVG plots for self-contained HTML reports: x–y lines and points,
// heat-maps over two binned drivers, grouped horizontal bars. Every function
// returns one <svg> element as text (no scripts, no external fonts or
// styles); NaN values are skipped.
#pragma once

#include <string>
#include <vector>

namespace pvtwin {

struct SvgSeries {
  std::string name;
  std::string color;  // CSS colour, e.g. "#1f77b4"
  std::vector<double> x, y;
  bool points = false;  // dots instead of a polyline (a NaN breaks a line)
};

struct SvgXYOptions {
  std::string title, x_label, y_label;
  double width = 760, height = 300;
  bool x_is_unix_time = false;    // x ticks as UTC dates/hours
  bool diagonal = false;          // draw y = x (measured vs predicted)
  std::size_t max_points = 4000;  // per series; longer series are thinned evenly
};

std::string SvgXYPlot(const std::vector<SvgSeries>& series, const SvgXYOptions& options);

struct SvgHeatmap {
  std::string title, x_label, y_label, value_label;
  std::vector<double> x_edges, y_edges;
  std::vector<double> values;  // (y_edges.size()−1) × (x_edges.size()−1), row = y bin; NaN = empty
  double width = 460, height = 300;
};

std::string SvgHeatmapPlot(const SvgHeatmap& map);

struct SvgBarGroup {
  std::string label;
  std::vector<double> values;  // one per bar series
};

// Horizontal grouped bars, values in [0, max]; series_names/colors per bar.
std::string SvgBarPlot(const std::string& title, const std::vector<std::string>& series_names,
                       const std::vector<std::string>& series_colors,
                       const std::vector<SvgBarGroup>& groups, double width = 760);

// Text escaped for XML/HTML.
std::string XmlEscape(const std::string& text);

}  // namespace pvtwin

#pragma once
// A small SVG writer for the report's figures: a frame with axes, ticks and labels, and in
// it lines, markers and horizontal interval bars given in data coordinates. Renders to one
// inline <svg> element: no script, no external reference, every text escaped.

#include <string>
#include <vector>

namespace slideid {

/// How a line, a marker or a bar is drawn.
struct SvgStyle {
  std::string color = "#1f77b4";  ///< a CSS colour (a literal: not escaped)
  double width_px = 1.5;          ///< stroke width
  bool dashed = false;
  double opacity = 1.0;
};

/// A figure of `width_px` x `height_px` (its viewBox; the page may scale it).
class SvgPlot {
 public:
  SvgPlot(int width_px, int height_px);

  void SetTitle(std::string title) { title_ = std::move(title); }
  void SetXLabel(std::string label) { x_label_ = std::move(label); }
  void SetYLabel(std::string label) { y_label_ = std::move(label); }
  /// One unit of x as long on the page as one of y (paths in the plane).
  void SetEqualAspect(bool on) { equal_aspect_ = on; }
  /// y on a log10 scale (costs); values <= 0 are left out.
  void SetLogY(bool on) { log_y_ = on; }
  /// y is a list of rows named `names`, the first at the top (y = 0, 1, ...): a forest plot.
  void SetYCategories(std::vector<std::string> names) { categories_ = std::move(names); }
  /// Includes `value` in the x range (a reference value that must show).
  void IncludeX(double value);

  /// A polyline through (x[i], y[i]); a non-finite point breaks it. Long lines are thinned
  /// to kMaxLinePoints. `legend` names it in the legend (none when empty).
  void AddLine(const std::vector<double>& x, const std::vector<double>& y, const SvgStyle& style,
               const std::string& legend = "");
  /// A marker at each finite (x[i], y[i]): "circle", "square" or "diamond", `size_px` across.
  void AddMarkers(const std::vector<double>& x, const std::vector<double>& y, const SvgStyle& style,
                  const std::string& shape = "circle", double size_px = 6,
                  const std::string& legend = "");
  /// A horizontal bar from lo to hi at y (an interval), with end ticks.
  void AddIntervalX(double y, double lo, double hi, const SvgStyle& style);
  /// A vertical line across the frame at x.
  void AddVerticalLine(double x, const SvgStyle& style, const std::string& legend = "");

  /// The figure as one <svg> element; `label` is its accessible name (escaped).
  std::string Render(const std::string& label) const;

 private:
  struct Item {
    enum Kind { kLine, kMarkers, kInterval, kVertical } kind = kLine;
    std::vector<double> x, y;
    SvgStyle style;
    std::string shape;
    double size_px = 6;
    std::string legend;
  };
  int width_, height_;
  std::string title_, x_label_, y_label_;
  bool equal_aspect_ = false, log_y_ = false;
  std::vector<std::string> categories_;
  std::vector<double> include_x_;
  std::vector<Item> items_;
};

/// Lines longer than this are thinned (every k-th point, the last kept): a figure of a
/// 10,000-row log stays a few hundred kB, and the eye sees no difference at this width.
constexpr int kMaxLinePoints = 1500;

/// The colours the report uses for its series, in order (colour-blind safe: Okabe-Ito).
const std::vector<std::string>& SeriesColors();

}  // namespace slideid

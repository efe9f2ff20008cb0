#include "report/svg_plot.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "forward_model/number_format.h"
#include "report/html_text.h"

namespace slideid {
namespace {

// The frame's margins [px]: room for the tick labels and the axis labels.
constexpr double kLeft = 64, kRight = 16, kTop = 28, kBottom = 44;
// Forest plots: the row names need room on the left, at most this share of the width.
constexpr double kMaxCategoryShare = 0.45;
// A range of zero width is opened by this fraction of its value (or by 1 at zero).
constexpr double kFlatRangeFraction = 0.05;
// Data ranges are padded by this fraction on each side, so that nothing sits on the frame.
constexpr double kPadFraction = 0.04;
// Labels and legends (11 px sans-serif) take about this many px per character.
constexpr double kCharPx = 6.2;
// About this many ticks per axis.
constexpr int kTargetTicks = 6;

struct Range {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void Include(double v) {
    if (!std::isfinite(v)) return;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  bool Empty() const { return !(lo <= hi); }
  void Settle() {
    if (Empty()) {
      lo = 0;
      hi = 1;
    }
    if (hi - lo <= 0) {
      const double open = lo != 0 ? std::abs(lo) * kFlatRangeFraction : 1.0;
      lo -= open;
      hi += open;
    }
    const double pad = (hi - lo) * kPadFraction;
    lo -= pad;
    hi += pad;
  }
};

// Round steps: 1, 2 or 5 times a power of ten, about kTargetTicks across the range.
double TickStep(double span) {
  const double raw = span / kTargetTicks;
  const double power = std::pow(10.0, std::floor(std::log10(raw)));
  for (const double m : {1.0, 2.0, 5.0}) {
    if (m * power >= raw) return m * power;
  }
  return 10 * power;
}

std::string Px(double v) { return Printf("%.1f", v); }

std::string Dash(const SvgStyle& s) {
  return s.dashed ? Printf(" stroke-dasharray=\"%.1f %.1f\"", 4 * s.width_px, 3 * s.width_px) : "";
}

std::string Opacity(const SvgStyle& s) {
  return s.opacity < 1 ? Printf(" opacity=\"%.2f\"", s.opacity) : "";
}

std::string TickLabel(double v, double step) {
  if (std::abs(v) < step * 1e-9) v = 0;  // no "-1.2e-17" at zero
  return Printf("%.4g", v);
}

}  // namespace

const std::vector<std::string>& SeriesColors() {
  static const std::vector<std::string> colors = {"#0072B2", "#D55E00", "#009E73", "#CC79A7",
                                                  "#E69F00", "#56B4E9", "#000000", "#F0E442"};
  return colors;
}

SvgPlot::SvgPlot(int width_px, int height_px) : width_(width_px), height_(height_px) {}

void SvgPlot::IncludeX(double value) { include_x_.push_back(value); }

void SvgPlot::AddLine(const std::vector<double>& x, const std::vector<double>& y,
                      const SvgStyle& style, const std::string& legend) {
  Item item;
  item.kind = Item::kLine;
  const size_t n = std::min(x.size(), y.size());
  const size_t stride = n > kMaxLinePoints ? (n + kMaxLinePoints - 1) / kMaxLinePoints : 1;
  for (size_t i = 0; i < n; i += stride) {
    item.x.push_back(x[i]);
    item.y.push_back(y[i]);
  }
  if (n > 0 && (n - 1) % stride != 0) {
    item.x.push_back(x[n - 1]);
    item.y.push_back(y[n - 1]);
  }
  item.style = style;
  item.legend = legend;
  items_.push_back(std::move(item));
}

void SvgPlot::AddMarkers(const std::vector<double>& x, const std::vector<double>& y,
                         const SvgStyle& style, const std::string& shape, double size_px,
                         const std::string& legend) {
  Item item;
  item.kind = Item::kMarkers;
  item.x = x;
  item.y = y;
  item.style = style;
  item.shape = shape;
  item.size_px = size_px;
  item.legend = legend;
  items_.push_back(std::move(item));
}

void SvgPlot::AddIntervalX(double y, double lo, double hi, const SvgStyle& style) {
  Item item;
  item.kind = Item::kInterval;
  item.x = {lo, hi};
  item.y = {y, y};
  item.style = style;
  items_.push_back(std::move(item));
}

void SvgPlot::AddVerticalLine(double x, const SvgStyle& style, const std::string& legend) {
  Item item;
  item.kind = Item::kVertical;
  item.x = {x};
  item.style = style;
  item.legend = legend;
  items_.push_back(std::move(item));
}

std::string SvgPlot::Render(const std::string& label) const {
  const bool categorical = !categories_.empty();
  size_t longest_name = 0;
  for (const std::string& name : categories_) longest_name = std::max(longest_name, name.size());
  const double left = categorical ? std::min(kMaxCategoryShare * width_,
                                             std::max(kLeft, 12 + kCharPx * longest_name))
                                  : kLeft;
  const double frame_w = width_ - left - kRight, frame_h = height_ - kTop - kBottom;
  auto ty = [&](double v) { return log_y_ ? (v > 0 ? std::log10(v) : std::nan("")) : v; };

  Range rx, ry;
  for (const double v : include_x_) rx.Include(v);
  for (const Item& item : items_) {
    for (size_t i = 0; i < item.x.size(); ++i) {
      const double y = item.kind == Item::kVertical ? 0.0 : ty(item.y[i]);
      if (!std::isfinite(item.x[i]) || !std::isfinite(y)) continue;
      rx.Include(item.x[i]);
      if (item.kind != Item::kVertical) ry.Include(y);
    }
  }
  rx.Settle();
  if (categorical) {
    ry.lo = -0.5;
    ry.hi = static_cast<double>(categories_.size()) - 0.5;
  } else {
    ry.Settle();
  }
  if (equal_aspect_) {
    // Widen the narrower span so that one unit is as long on both axes.
    const double per_px = std::max((rx.hi - rx.lo) / frame_w, (ry.hi - ry.lo) / frame_h);
    const double cx = (rx.lo + rx.hi) / 2, cy = (ry.lo + ry.hi) / 2;
    rx.lo = cx - per_px * frame_w / 2;
    rx.hi = cx + per_px * frame_w / 2;
    ry.lo = cy - per_px * frame_h / 2;
    ry.hi = cy + per_px * frame_h / 2;
  }
  auto X = [&](double v) { return left + (v - rx.lo) / (rx.hi - rx.lo) * frame_w; };
  // Categories run from the top; numbers from the bottom.
  auto Y = [&](double v) {
    return categorical ? kTop + (v - ry.lo) / (ry.hi - ry.lo) * frame_h
                       : kTop + (ry.hi - v) / (ry.hi - ry.lo) * frame_h;
  };

  std::ostringstream svg;
  svg << "<svg class=\"figure\" viewBox=\"0 0 " << width_ << ' ' << height_ << "\" width=\""
      << width_ << "\" height=\"" << height_ << "\" role=\"img\" aria-label=\"" << HtmlEscape(label)
      << "\">";
  svg << "<title>" << HtmlEscape(title_.empty() ? label : title_) << "</title>";
  svg << "<rect x=\"" << Px(left) << "\" y=\"" << Px(kTop) << "\" width=\"" << Px(frame_w)
      << "\" height=\"" << Px(frame_h) << "\" fill=\"#fff\" stroke=\"#888\"/>";
  if (!title_.empty()) {
    svg << "<text x=\"" << Px(left) << "\" y=\"18\" class=\"fig-title\">" << HtmlEscape(title_)
        << "</text>";
  }
  // Ticks and grid.
  const double xs = TickStep(rx.hi - rx.lo);
  for (double v = std::ceil(rx.lo / xs) * xs; v <= rx.hi; v += xs) {
    svg << "<line x1=\"" << Px(X(v)) << "\" x2=\"" << Px(X(v)) << "\" y1=\"" << Px(kTop)
        << "\" y2=\"" << Px(kTop + frame_h) << "\" class=\"grid\"/>";
    svg << "<text x=\"" << Px(X(v)) << "\" y=\"" << Px(kTop + frame_h + 14)
        << "\" text-anchor=\"middle\" class=\"tick\">" << HtmlEscape(TickLabel(v, xs)) << "</text>";
  }
  if (categorical) {
    for (size_t k = 0; k < categories_.size(); ++k) {
      svg << "<text x=\"" << Px(left - 6) << "\" y=\"" << Px(Y(k) + 4)
          << "\" text-anchor=\"end\" class=\"tick\">" << HtmlEscape(categories_[k]) << "</text>";
    }
  } else {
    const double ys =
        log_y_ ? std::max(1.0, std::round(TickStep(ry.hi - ry.lo))) : TickStep(ry.hi - ry.lo);
    for (double v = std::ceil(ry.lo / ys) * ys; v <= ry.hi; v += ys) {
      svg << "<line x1=\"" << Px(left) << "\" x2=\"" << Px(left + frame_w) << "\" y1=\"" << Px(Y(v))
          << "\" y2=\"" << Px(Y(v)) << "\" class=\"grid\"/>";
      const std::string text =
          log_y_ ? Printf("1e%d", static_cast<int>(std::lround(v))) : TickLabel(v, ys);
      svg << "<text x=\"" << Px(left - 6) << "\" y=\"" << Px(Y(v) + 4)
          << "\" text-anchor=\"end\" class=\"tick\">" << HtmlEscape(text) << "</text>";
    }
  }
  if (!x_label_.empty()) {
    svg << "<text x=\"" << Px(left + frame_w / 2) << "\" y=\"" << Px(height_ - 8)
        << "\" text-anchor=\"middle\" class=\"axis-label\">" << HtmlEscape(x_label_) << "</text>";
  }
  if (!y_label_.empty()) {
    svg << "<text transform=\"translate(14," << Px(kTop + frame_h / 2)
        << ") rotate(-90)\" text-anchor=\"middle\" class=\"axis-label\">" << HtmlEscape(y_label_)
        << "</text>";
  }
  // The data, clipped to the frame (a clip path per figure would need unique ids: the frame
  // is padded instead, and equal-aspect paths stay inside it by construction).
  for (const Item& item : items_) {
    const SvgStyle& s = item.style;
    switch (item.kind) {
      case Item::kLine: {
        std::string points;
        auto flush = [&]() {
          if (!points.empty()) {
            svg << "<polyline fill=\"none\" stroke=\"" << s.color << "\" stroke-width=\""
                << Px(s.width_px) << "\"" << Dash(s) << Opacity(s) << " points=\"" << points
                << "\"/>";
          }
          points.clear();
        };
        for (size_t i = 0; i < item.x.size(); ++i) {
          const double y = ty(item.y[i]);
          if (!std::isfinite(item.x[i]) || !std::isfinite(y)) {
            flush();
            continue;
          }
          points += (points.empty() ? "" : " ") + Px(X(item.x[i])) + "," + Px(Y(y));
        }
        flush();
        break;
      }
      case Item::kMarkers:
        for (size_t i = 0; i < item.x.size(); ++i) {
          const double y = ty(item.y[i]);
          if (!std::isfinite(item.x[i]) || !std::isfinite(y)) continue;
          const double cx = X(item.x[i]), cy = Y(y), r = item.size_px / 2;
          if (item.shape == "square") {
            svg << "<rect x=\"" << Px(cx - r) << "\" y=\"" << Px(cy - r) << "\" width=\""
                << Px(2 * r) << "\" height=\"" << Px(2 * r) << "\" fill=\"" << s.color << "\""
                << Opacity(s) << "/>";
          } else if (item.shape == "diamond") {
            svg << "<polygon points=\"" << Px(cx) << "," << Px(cy - r) << " " << Px(cx + r) << ","
                << Px(cy) << " " << Px(cx) << "," << Px(cy + r) << " " << Px(cx - r) << ","
                << Px(cy) << "\" fill=\"" << s.color << "\"" << Opacity(s) << "/>";
          } else {
            svg << "<circle cx=\"" << Px(cx) << "\" cy=\"" << Px(cy) << "\" r=\"" << Px(r)
                << "\" fill=\"" << s.color << "\"" << Opacity(s) << "/>";
          }
        }
        break;
      case Item::kInterval: {
        if (!std::isfinite(item.x[0]) || !std::isfinite(item.x[1])) break;
        const double y = Y(item.y[0]), x0 = X(item.x[0]), x1 = X(item.x[1]);
        svg << "<path fill=\"none\" stroke=\"" << s.color << "\" stroke-width=\"" << Px(s.width_px)
            << "\"" << Dash(s) << Opacity(s) << " d=\"M" << Px(x0) << "," << Px(y) << "H" << Px(x1)
            << "M" << Px(x0) << "," << Px(y - 4) << "V" << Px(y + 4) << "M" << Px(x1) << ","
            << Px(y - 4) << "V" << Px(y + 4) << "\"/>";
        break;
      }
      case Item::kVertical:
        if (!std::isfinite(item.x[0])) break;
        svg << "<line x1=\"" << Px(X(item.x[0])) << "\" x2=\"" << Px(X(item.x[0])) << "\" y1=\""
            << Px(kTop) << "\" y2=\"" << Px(kTop + frame_h) << "\" stroke=\"" << s.color
            << "\" stroke-width=\"" << Px(s.width_px) << "\"" << Dash(s) << Opacity(s) << "/>";
        break;
    }
  }
  // The legend, top right inside the frame, on a veil that keeps the data behind it legible.
  int entries = 0;
  size_t longest = 0;
  for (const Item& item : items_) {
    if (item.legend.empty()) continue;
    ++entries;
    longest = std::max(longest, item.legend.size());
  }
  if (entries > 0) {
    const double w = 40 + kCharPx * longest, h = 6 + 15 * entries;
    svg << "<rect x=\"" << Px(left + frame_w - 4 - w) << "\" y=\"" << Px(kTop + 2) << "\" width=\""
        << Px(w) << "\" height=\"" << Px(h) << "\" fill=\"#fff\" opacity=\"0.85\"/>";
  }
  int row = 0;
  for (const Item& item : items_) {
    if (item.legend.empty()) continue;
    const double y = kTop + 14 + 15 * row++;
    const double x = left + frame_w - 8;
    svg << "<line x1=\"" << Px(x - 22) << "\" x2=\"" << Px(x) << "\" y1=\"" << Px(y - 4)
        << "\" y2=\"" << Px(y - 4) << "\" stroke=\"" << item.style.color << "\" stroke-width=\""
        << Px(std::max(2.0, item.style.width_px)) << "\"" << Dash(item.style) << "/>";
    svg << "<text x=\"" << Px(x - 26) << "\" y=\"" << Px(y) << "\" text-anchor=\"end\""
        << " class=\"legend\">" << HtmlEscape(item.legend) << "</text>";
  }
  svg << "</svg>";
  return svg.str();
}

}  // namespace slideid

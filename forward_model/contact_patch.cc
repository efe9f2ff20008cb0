#include "forward_model/contact_patch.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "forward_model/constants.h"
#include "forward_model/number_format.h"

namespace slideid {
namespace {

using Vec2 = Eigen::Vector2d;

void RequirePositive(const char* what, double value) {
  if (!std::isfinite(value) || value <= 0.0) {
    throw std::invalid_argument(std::string("contact patch: ") + what + " = " + ExactNumber(value) +
                                ": must be finite and > 0");
  }
}

/// z of (b - a) x (c - a): > 0 when a, b, c turn counter-clockwise.
double Cross(const Vec2& a, const Vec2& b, const Vec2& c) {
  return (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
}

/// True when q, known to be collinear with segment ab, lies on it.
bool OnSegment(const Vec2& a, const Vec2& b, const Vec2& q) {
  return std::min(a.x(), b.x()) <= q.x() && q.x() <= std::max(a.x(), b.x()) &&
         std::min(a.y(), b.y()) <= q.y() && q.y() <= std::max(a.y(), b.y());
}

/// Closed segments ab and cd share at least one point (touching counts).
bool SegmentsIntersect(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
  const double d1 = Cross(c, d, a), d2 = Cross(c, d, b);
  const double d3 = Cross(a, b, c), d4 = Cross(a, b, d);
  if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0))) {
    return true;
  }
  return (d1 == 0 && OnSegment(c, d, a)) || (d2 == 0 && OnSegment(c, d, b)) ||
         (d3 == 0 && OnSegment(a, b, c)) || (d4 == 0 && OnSegment(a, b, d));
}

/// Shoelace formula: positive for a counter-clockwise polygon.
double SignedArea(const std::vector<Vec2>& v) {
  double twice = 0.0;
  for (size_t i = 0; i < v.size(); ++i) {
    const Vec2& p = v[i];
    const Vec2& q = v[(i + 1) % v.size()];
    twice += p.x() * q.y() - q.x() * p.y();
  }
  return 0.5 * twice;
}

std::string VertexText(size_t i, const Vec2& p) {
  return "vertex " + std::to_string(i) + " (" + ExactNumber(p.x()) + ", " + ExactNumber(p.y()) +
         ")";
}

void CheckVerticesFinite(const std::vector<Vec2>& v) {
  for (size_t i = 0; i < v.size(); ++i) {
    if (!v[i].allFinite()) {
      throw std::invalid_argument("contact patch: polygon " + VertexText(i, v[i]) +
                                  " is not finite");
    }
  }
}

/// All vertices on one line: report zero area before the edge checks call it a fold.
void CheckNotCollinear(const std::vector<Vec2>& v) {
  const auto other = std::find_if(v.begin(), v.end(), [&](const Vec2& p) { return p != v[0]; });
  for (auto it = other; it != v.end(); ++it) {
    if (Cross(v[0], *other, *it) != 0.0) return;
  }
  throw std::invalid_argument("contact patch: polygon has zero area (all vertices collinear)");
}

/// Adjacent edges may only share their common vertex: reject zero-length edges and
/// edges that fold back onto the previous one.
void CheckAdjacentEdges(const std::vector<Vec2>& v) {
  const size_t n = v.size();
  for (size_t i = 0; i < n; ++i) {
    const Vec2& a = v[i];
    const Vec2& b = v[(i + 1) % n];
    const Vec2& c = v[(i + 2) % n];
    if (a == b) {
      throw std::invalid_argument("contact patch: polygon " + VertexText(i, a) +
                                  " repeats the next vertex (zero-length edge)");
    }
    if (Cross(a, b, c) == 0.0 && (b - a).dot(c - b) < 0.0) {
      throw std::invalid_argument("contact patch: polygon is self-intersecting: edge at " +
                                  VertexText((i + 1) % n, b) + " folds back on itself");
    }
  }
}

/// Every pair of non-adjacent edges must be disjoint (O(n^2); patches are small).
void CheckNonAdjacentEdges(const std::vector<Vec2>& v) {
  const size_t n = v.size();
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;  // edges n-1 and 0 share vertex 0
      if (SegmentsIntersect(v[i], v[(i + 1) % n], v[j], v[(j + 1) % n])) {
        throw std::invalid_argument("contact patch: polygon is self-intersecting: edge from " +
                                    VertexText(i, v[i]) + " meets edge from " +
                                    VertexText(j, v[j]));
      }
    }
  }
}

void CheckOrientation(const std::vector<Vec2>& v) {
  const double area = SignedArea(v);
  if (area == 0.0) {
    throw std::invalid_argument("contact patch: polygon has zero area");
  }
  if (area < 0.0) {
    throw std::invalid_argument("contact patch: polygon signed area = " + ExactNumber(area) +
                                ": vertices are clockwise; they must be counter-clockwise");
  }
}

/// Andrew's monotone chain; collinear points are dropped. Result is CCW.
std::vector<Vec2> ConvexHull(std::vector<Vec2> points) {
  std::sort(points.begin(), points.end(), [](const Vec2& a, const Vec2& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  std::vector<Vec2> hull(2 * points.size());
  size_t k = 0;
  for (size_t i = 0; i < points.size(); ++i) {  // lower chain
    while (k >= 2 && Cross(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  for (size_t i = points.size() - 1, lower = k + 1; i-- > 0;) {  // upper chain
    while (k >= lower && Cross(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  hull.resize(k - 1);  // the last point repeats the first
  return hull;
}

double DistanceToSegment(const Vec2& p, const Vec2& a, const Vec2& b) {
  const Vec2 ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (p - (a + t * ab)).norm();
}

/// Signed distance to a CCW convex polygon's boundary.
double SignedDistanceToConvex(const std::vector<Vec2>& hull, const Vec2& p) {
  double distance = std::numeric_limits<double>::infinity();
  bool inside = true;
  for (size_t i = 0; i < hull.size(); ++i) {
    const Vec2& a = hull[i];
    const Vec2& b = hull[(i + 1) % hull.size()];
    distance = std::min(distance, DistanceToSegment(p, a, b));
    if (Cross(a, b, p) < 0.0) inside = false;
  }
  return inside ? -distance : distance;
}

std::vector<Vec2> Circle(double radius, int segments) {
  if (segments < 3) {
    throw std::invalid_argument("contact patch: circle_segments = " + std::to_string(segments) +
                                ": must be >= 3");
  }
  std::vector<Vec2> out;
  for (int i = 0; i <= segments; ++i) {
    const double phi = 2.0 * kPi * i / segments;
    out.emplace_back(radius * std::cos(phi), radius * std::sin(phi));
  }
  return out;
}

/// Parses one number token in full; "0.05abc" and "nan" are errors.
double ParseNumber(const std::string& token, const std::string& spec) {
  char* end = nullptr;
  const double value = std::strtod(token.c_str(), &end);
  if (token.empty() || *end != '\0' || !std::isfinite(value)) {
    throw std::invalid_argument("contact patch \"" + spec + "\": '" + token +
                                "' is not a finite number");
  }
  return value;
}

void RequireCount(const std::string& spec, const std::string& shape, size_t got, size_t want) {
  if (got != want) {
    throw std::invalid_argument("contact patch \"" + spec + "\": " + shape + " takes " +
                                std::to_string(want) + " numbers, got " + std::to_string(got));
  }
}

ContactPatch PolygonFromNumbers(const std::vector<double>& numbers, const std::string& spec) {
  if (numbers.size() % 2 != 0 || numbers.size() < 6) {
    throw std::invalid_argument("contact patch \"" + spec +
                                "\": polygon takes an even number (>= 6) of coordinates, got " +
                                std::to_string(numbers.size()));
  }
  std::vector<Vec2> vertices;
  for (size_t i = 0; i < numbers.size(); i += 2) vertices.emplace_back(numbers[i], numbers[i + 1]);
  return ContactPatch::Polygon(vertices);
}

}  // namespace

ContactPatch ContactPatch::Rectangle(double width_m, double length_m) {
  RequirePositive("rectangle width", width_m);
  RequirePositive("rectangle length", length_m);
  ContactPatch patch;
  patch.shape_ = Shape::kRectangle;
  patch.width_m_ = width_m;
  patch.length_m_ = length_m;
  const double hw = 0.5 * width_m, hl = 0.5 * length_m;
  patch.hull_ = {Vec2(-hw, -hl), Vec2(hw, -hl), Vec2(hw, hl), Vec2(-hw, hl)};
  return patch;
}

ContactPatch ContactPatch::Disk(double radius_m) {
  RequirePositive("disk radius", radius_m);
  ContactPatch patch;
  patch.shape_ = Shape::kDisk;
  patch.radius_m_ = radius_m;
  return patch;
}

ContactPatch ContactPatch::Ring(double outer_radius_m, double inner_radius_m) {
  RequirePositive("ring outer radius", outer_radius_m);
  if (!std::isfinite(inner_radius_m) || inner_radius_m < 0.0 || inner_radius_m >= outer_radius_m) {
    throw std::invalid_argument(
        "contact patch: ring inner radius = " + ExactNumber(inner_radius_m) +
        ": must be >= 0 and < the outer radius " + ExactNumber(outer_radius_m));
  }
  ContactPatch patch;
  patch.shape_ = Shape::kRing;
  patch.radius_m_ = outer_radius_m;
  patch.inner_radius_m_ = inner_radius_m;
  return patch;
}

ContactPatch ContactPatch::Polygon(const std::vector<Eigen::Vector2d>& vertices_ccw) {
  if (vertices_ccw.size() < 3) {
    throw std::invalid_argument("contact patch: polygon has " +
                                std::to_string(vertices_ccw.size()) +
                                " vertices; it needs at least 3");
  }
  CheckVerticesFinite(vertices_ccw);
  CheckNotCollinear(vertices_ccw);
  CheckAdjacentEdges(vertices_ccw);
  CheckNonAdjacentEdges(vertices_ccw);
  CheckOrientation(vertices_ccw);
  ContactPatch patch;
  patch.shape_ = Shape::kPolygon;
  patch.vertices_ = vertices_ccw;
  patch.hull_ = ConvexHull(vertices_ccw);
  return patch;
}

ContactPatch ContactPatch::Parse(const std::string& spec) {
  std::istringstream in(spec);
  std::string shape, token;
  if (!(in >> shape)) throw std::invalid_argument("contact patch: empty specification");
  std::vector<double> numbers;
  while (in >> token) numbers.push_back(ParseNumber(token, spec));
  if (shape == "rectangle") {
    RequireCount(spec, shape, numbers.size(), 2);
    return Rectangle(numbers[0], numbers[1]);
  }
  if (shape == "disk") {
    RequireCount(spec, shape, numbers.size(), 1);
    return Disk(numbers[0]);
  }
  if (shape == "ring") {
    RequireCount(spec, shape, numbers.size(), 2);
    return Ring(numbers[0], numbers[1]);
  }
  if (shape == "polygon") return PolygonFromNumbers(numbers, spec);
  throw std::invalid_argument("contact patch \"" + spec + "\": unknown shape '" + shape +
                              "' (rectangle, disk, ring or polygon)");
}

std::string ContactPatch::Spec() const {
  switch (shape_) {
    case Shape::kRectangle:
      return "rectangle " + ExactNumber(width_m_) + " " + ExactNumber(length_m_);
    case Shape::kDisk:
      return "disk " + ExactNumber(radius_m_);
    case Shape::kRing:
      return "ring " + ExactNumber(radius_m_) + " " + ExactNumber(inner_radius_m_);
    case Shape::kPolygon:
      break;
  }
  std::string out = "polygon";
  for (const Vec2& v : vertices_) out += " " + ExactNumber(v.x()) + " " + ExactNumber(v.y());
  return out;
}

double ContactPatch::SignedDistanceToHull(const Eigen::Vector2d& p_body) const {
  // A ring's hull is its outer disk: the hole does not matter for toppling.
  if (shape_ == Shape::kDisk || shape_ == Shape::kRing) return p_body.norm() - radius_m_;
  return SignedDistanceToConvex(hull_, p_body);
}

std::vector<Eigen::Vector2d> ContactPatch::Outline(int circle_segments) const {
  if (shape_ == Shape::kDisk || shape_ == Shape::kRing) return Circle(radius_m_, circle_segments);
  std::vector<Vec2> out = shape_ == Shape::kPolygon ? vertices_ : hull_;
  out.push_back(out.front());  // closed: last point repeats the first
  return out;
}

std::vector<Eigen::Vector2d> ContactPatch::InnerOutline(int circle_segments) const {
  if (shape_ != Shape::kRing || inner_radius_m_ == 0.0) return {};
  return Circle(inner_radius_m_, circle_segments);
}

double ContactPatch::Area() const {
  switch (shape_) {
    case Shape::kRectangle:
      return width_m_ * length_m_;
    case Shape::kDisk:
      return kPi * radius_m_ * radius_m_;
    case Shape::kRing:
      return kPi * (radius_m_ * radius_m_ - inner_radius_m_ * inner_radius_m_);
    case Shape::kPolygon:
      break;
  }
  return SignedArea(vertices_);
}

}  // namespace slideid

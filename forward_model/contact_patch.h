#pragma once
// The contact patch between slider and support, in the body frame, and the convex hull
// that the ECP must stay inside (model.md, "No-toppling check").

#include <Eigen/Core>
#include <string>
#include <vector>

namespace slideid {

/// A patch: rectangle, disk, ring (non-convex) or simple polygon, body frame, centred
/// on the CM's projection. Immutable after construction; constructors validate and throw
/// std::invalid_argument naming the bad value.
class ContactPatch {
 public:
  enum class Shape { kRectangle, kDisk, kRing, kPolygon };

  /// width along body x, length along body y [m], both > 0.
  static ContactPatch Rectangle(double width_m, double length_m);
  static ContactPatch Disk(double radius_m);
  /// Annulus with 0 <= inner < outer.
  static ContactPatch Ring(double outer_radius_m, double inner_radius_m);
  /// Simple (non-self-intersecting) polygon, >= 3 vertices, counter-clockwise, area > 0.
  static ContactPatch Polygon(const std::vector<Eigen::Vector2d>& vertices_ccw);
  /// Parses the log-format metadata form: "rectangle W L", "disk R", "ring R R_inner",
  /// "polygon x1 y1 x2 y2 ...". Throws std::invalid_argument on bad text.
  static ContactPatch Parse(const std::string& spec);

  Shape shape() const { return shape_; }
  /// The metadata form that Parse reads back (full precision).
  std::string Spec() const;
  /// Signed distance from p (body frame) to the boundary of the patch's convex hull [m]:
  /// negative inside, positive outside.
  double SignedDistanceToHull(const Eigen::Vector2d& p_body) const;
  /// True when p lies in the convex hull, allowing `tolerance_m` outside.
  bool HullContains(const Eigen::Vector2d& p_body, double tolerance_m = 0.0) const {
    return SignedDistanceToHull(p_body) <= tolerance_m;
  }
  /// Outer boundary as a closed polyline (circles sampled with `circle_segments`), body
  /// frame, for plots. Rings also give the inner circle via InnerOutline.
  std::vector<Eigen::Vector2d> Outline(int circle_segments = 72) const;
  std::vector<Eigen::Vector2d> InnerOutline(int circle_segments = 72) const;
  /// Area of the patch itself [m^2] (ring: annulus).
  double Area() const;
  /// The outer radius of a disk or ring [m]; 0 for the other shapes.
  double OuterRadius() const {
    return shape_ == Shape::kDisk || shape_ == Shape::kRing ? radius_m_ : 0.0;
  }

 private:
  ContactPatch() = default;
  Shape shape_ = Shape::kRectangle;
  double width_m_ = 0, length_m_ = 0, radius_m_ = 0, inner_radius_m_ = 0;
  std::vector<Eigen::Vector2d> vertices_;  // polygon as given
  std::vector<Eigen::Vector2d> hull_;      // CCW convex hull for polygon and rectangle
};

}  // namespace slideid

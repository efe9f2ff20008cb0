#include "forward_model/contact_patch.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "forward_model/constants.h"

namespace slideid {
namespace {

using Vec2 = Eigen::Vector2d;

/// Distances here are sums of a few products of short decimals: exact to a few ulps.
constexpr double kTol = 1e-12;

/// An L-shaped patch (non-convex): a 2 x 2 square with the top-right 1 x 1 quarter cut away.
std::vector<Vec2> LShape() {
  return {Vec2(0, 0), Vec2(2, 0), Vec2(2, 1), Vec2(1, 1), Vec2(1, 2), Vec2(0, 2)};
}

/// Runs `f` and returns the std::invalid_argument message ("" if none was thrown).
template <typename F>
std::string InvalidArgumentMessage(F f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(ContactPatch, RectangleHullDistanceIsNegativeInsideZeroOnEdgePositiveOutside) {
  const ContactPatch p = ContactPatch::Rectangle(0.05, 0.1);  // half sizes 0.025, 0.05
  EXPECT_NEAR(p.SignedDistanceToHull(Vec2(0, 0)), -0.025, kTol);
  EXPECT_NEAR(p.SignedDistanceToHull(Vec2(0.02, 0.0)), -0.005, kTol);
  EXPECT_NEAR(p.SignedDistanceToHull(Vec2(0.025, 0.01)), 0.0, kTol);
  EXPECT_NEAR(p.SignedDistanceToHull(Vec2(0.0, 0.06)), 0.01, kTol);
  // Outside a corner the distance is to the corner, not to either edge line.
  EXPECT_NEAR(p.SignedDistanceToHull(Vec2(0.028, 0.054)), 0.005, kTol);
  EXPECT_TRUE(p.HullContains(Vec2(0.025, 0.05)));
  EXPECT_FALSE(p.HullContains(Vec2(0.026, 0.0)));
  EXPECT_TRUE(p.HullContains(Vec2(0.026, 0.0), 0.002));
}

TEST(ContactPatch, RectangleWidthIsAlongBodyX) {
  const ContactPatch p = ContactPatch::Rectangle(0.2, 0.04);
  EXPECT_TRUE(p.HullContains(Vec2(0.09, 0.0)));
  EXPECT_FALSE(p.HullContains(Vec2(0.0, 0.09)));
}

TEST(ContactPatch, DiskHullDistanceIsRadialDistanceMinusRadius) {
  const ContactPatch p = ContactPatch::Disk(0.1);
  EXPECT_NEAR(p.SignedDistanceToHull(Vec2(0, 0)), -0.1, kTol);
  EXPECT_NEAR(p.SignedDistanceToHull(Vec2(0.3, 0.4)), 0.4, kTol);
  EXPECT_NEAR(p.SignedDistanceToHull(Vec2(0.06, -0.08)), 0.0, kTol);
}

TEST(ContactPatch, RingHoleCentreIsInsideTheHull) {
  const ContactPatch p = ContactPatch::Ring(0.1, 0.05);
  EXPECT_NEAR(p.SignedDistanceToHull(Vec2(0, 0)), -0.1, kTol);
  EXPECT_TRUE(p.HullContains(Vec2(0.02, 0.01)));  // in the hole, still in the hull
  EXPECT_NEAR(p.SignedDistanceToHull(Vec2(0.0, 0.12)), 0.02, kTol);
}

TEST(ContactPatch, NonConvexPolygonHullContainsTheNotch) {
  const ContactPatch p = ContactPatch::Polygon(LShape());
  // (1.5, 1.5) is in the cut-away quarter: outside the patch, inside its hull, whose
  // boundary there is the diagonal x + y = 3, at distance 0 / sqrt(2).
  EXPECT_TRUE(p.HullContains(Vec2(1.5, 1.5)));
  EXPECT_NEAR(p.SignedDistanceToHull(Vec2(1.5, 1.5)), 0.0, kTol);
  EXPECT_NEAR(p.SignedDistanceToHull(Vec2(1.2, 1.2)), -0.6 / std::sqrt(2.0), kTol);
  EXPECT_NEAR(p.SignedDistanceToHull(Vec2(2.0, 2.0)), 1.0 / std::sqrt(2.0), kTol);
  EXPECT_NEAR(p.SignedDistanceToHull(Vec2(-1.0, 0.5)), 1.0, kTol);
}

TEST(ContactPatch, PolygonHullDropsCollinearAndInteriorVertices) {
  // A square given with a mid-edge vertex and a notch vertex: hull is the square.
  const ContactPatch p = ContactPatch::Polygon(
      {Vec2(0, 0), Vec2(1, 0), Vec2(2, 0), Vec2(2, 2), Vec2(1, 1.5), Vec2(0, 2)});
  EXPECT_NEAR(p.SignedDistanceToHull(Vec2(1, 1)), -1.0, kTol);
  EXPECT_NEAR(p.SignedDistanceToHull(Vec2(1, 2)), 0.0, kTol);
}

TEST(ContactPatch, SelfIntersectingPolygonIsRejected) {
  const std::string bowtie = InvalidArgumentMessage([] {
    ContactPatch::Polygon({Vec2(0, 0), Vec2(1, 1), Vec2(1, 0), Vec2(0, 1)});
  });
  EXPECT_NE(bowtie.find("self-intersecting"), std::string::npos) << bowtie;
  // A vertex touching a non-adjacent edge is not simple either.
  const std::string touching = InvalidArgumentMessage([] {
    ContactPatch::Polygon({Vec2(0, 0), Vec2(2, 0), Vec2(2, 2), Vec2(1, 0), Vec2(0, 2)});
  });
  EXPECT_NE(touching.find("self-intersecting"), std::string::npos) << touching;
}

TEST(ContactPatch, ClockwisePolygonIsRejectedSayingCounterClockwise) {
  const std::string message = InvalidArgumentMessage([] {
    ContactPatch::Polygon({Vec2(0, 0), Vec2(0, 1), Vec2(1, 1), Vec2(1, 0)});
  });
  EXPECT_NE(message.find("counter-clockwise"), std::string::npos) << message;
}

TEST(ContactPatch, DegeneratePolygonsAreRejected) {
  EXPECT_THROW(ContactPatch::Polygon({Vec2(0, 0), Vec2(1, 0), Vec2(2, 0)}),
               std::invalid_argument);  // zero area
  EXPECT_THROW(ContactPatch::Polygon({Vec2(0, 0), Vec2(1, 0)}), std::invalid_argument);
  EXPECT_THROW(ContactPatch::Polygon({Vec2(0, 0), Vec2(1, 0), Vec2(1, 0), Vec2(0, 1)}),
               std::invalid_argument);  // repeated vertex
  EXPECT_THROW(ContactPatch::Polygon({Vec2(0, 0), Vec2(NAN, 0), Vec2(0, 1)}),
               std::invalid_argument);
}

TEST(ContactPatch, RingInnerRadiusMustBeBelowOuter) {
  const std::string equal = InvalidArgumentMessage([] { ContactPatch::Ring(0.1, 0.1); });
  EXPECT_NE(equal.find("0.10000000000000001"), std::string::npos) << equal;
  EXPECT_THROW(ContactPatch::Ring(0.1, 0.2), std::invalid_argument);
  EXPECT_THROW(ContactPatch::Ring(0.1, -0.01), std::invalid_argument);
  EXPECT_NO_THROW(ContactPatch::Ring(0.1, 0.0));
}

TEST(ContactPatch, NonPositiveOrNonFiniteSizesAreRejectedNamingTheValue) {
  const std::string message = InvalidArgumentMessage([] { ContactPatch::Rectangle(0.05, -2); });
  EXPECT_NE(message.find("length = -2"), std::string::npos) << message;
  EXPECT_THROW(ContactPatch::Rectangle(0.0, 0.05), std::invalid_argument);
  EXPECT_THROW(ContactPatch::Disk(INFINITY), std::invalid_argument);
  EXPECT_THROW(ContactPatch::Disk(0.0), std::invalid_argument);
}

TEST(ContactPatch, ParseOfSpecRoundTripsEveryShapeAtFullPrecision) {
  const std::vector<ContactPatch> patches = {
      ContactPatch::Rectangle(0.1 / 3.0, 0.05), ContactPatch::Disk(std::sqrt(2.0) / 10),
      ContactPatch::Ring(0.1, 0.05), ContactPatch::Polygon(LShape())};
  for (const ContactPatch& p : patches) {
    const ContactPatch q = ContactPatch::Parse(p.Spec());
    EXPECT_EQ(q.Spec(), p.Spec());
    EXPECT_EQ(q.shape(), p.shape());
    EXPECT_EQ(q.Area(), p.Area());
    EXPECT_EQ(q.SignedDistanceToHull(Vec2(0.01, 0.02)), p.SignedDistanceToHull(Vec2(0.01, 0.02)));
  }
  EXPECT_EQ(ContactPatch::Rectangle(0.05, 0.05).Spec(),
            "rectangle 0.050000000000000003 0.050000000000000003");
}

TEST(ContactPatch, ParseRejectsBadTextNamingTheProblem) {
  EXPECT_NE(InvalidArgumentMessage([] { ContactPatch::Parse("hexagon 1"); }).find("hexagon"),
            std::string::npos);
  EXPECT_NE(InvalidArgumentMessage([] { ContactPatch::Parse("disk 0.1x"); }).find("0.1x"),
            std::string::npos);
  EXPECT_NE(InvalidArgumentMessage([] { ContactPatch::Parse("rectangle 1"); }).find("got 1"),
            std::string::npos);
  EXPECT_THROW(ContactPatch::Parse(""), std::invalid_argument);
  EXPECT_THROW(ContactPatch::Parse("polygon 0 0 1 0 1"), std::invalid_argument);
  EXPECT_THROW(ContactPatch::Parse("ring 0.1 nan"), std::invalid_argument);
}

TEST(ContactPatch, AreaMatchesTheShapeFormulas) {
  EXPECT_NEAR(ContactPatch::Rectangle(0.05, 0.1).Area(), 0.005, kTol);
  EXPECT_NEAR(ContactPatch::Disk(0.1).Area(), kPi * 0.01, kTol);
  EXPECT_NEAR(ContactPatch::Ring(0.1, 0.05).Area(), kPi * 0.0075, kTol);
  EXPECT_NEAR(ContactPatch::Polygon(LShape()).Area(), 3.0, kTol);
}

TEST(ContactPatch, OutlinesAreClosedAndLieOnTheBoundary) {
  const std::vector<Vec2> square = ContactPatch::Rectangle(2, 4).Outline();
  ASSERT_EQ(square.size(), 5u);
  EXPECT_EQ(square.front(), square.back());
  EXPECT_EQ(square[2], Vec2(1, 2));
  const ContactPatch ring = ContactPatch::Ring(0.1, 0.05);
  const std::vector<Vec2> outer = ring.Outline(36), inner = ring.InnerOutline(36);
  ASSERT_EQ(outer.size(), 37u);
  ASSERT_EQ(inner.size(), 37u);
  for (const Vec2& v : outer) EXPECT_NEAR(v.norm(), 0.1, kTol);
  for (const Vec2& v : inner) EXPECT_NEAR(v.norm(), 0.05, kTol);
  EXPECT_TRUE(ContactPatch::Disk(0.1).InnerOutline().empty());
  EXPECT_EQ(ContactPatch::Polygon(LShape()).Outline().size(), 7u);
}

}  // namespace
}  // namespace slideid

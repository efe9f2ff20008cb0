#pragma once
// Scenes with known friction for estimator tests: generate, identify, compare with truth.
// Each stays well inside its patch hull and slides for most of its steps.

#include <gtest/gtest.h>

#include <string>

#include "forward_model/scene.h"
#include "forward_model/simulator.h"

namespace slideid::testing {

inline Scene BaseScene() {
  Scene s;
  s.source = "synthetic";
  s.slider = {1.0, 1.0 * (0.1 * 0.1 + 0.1 * 0.1) / 12, 0.03, 9.81};
  s.friction = {0.3, 1.0, 1.0, 0.03};
  s.patch = ContactPatch::Rectangle(0.1, 0.1);
  s.dt_s = 0.01;
  s.duration_s = 0.5;
  return s;
}

/// Free slide with spin and velocity off both axes: a, b, c all identifiable.
inline Scene FreeSlideWithSpin() {
  Scene s = BaseScene();
  s.initial = {0, 0, 0, 1.2, 0.8, 12.0};
  s.duration_s = 0.45;
  return s;
}

/// Pushed off-centre with a periodic push: rotation, stick-slip.
inline Scene PushedSlider() {
  Scene s = BaseScene();
  s.initial = {0, 0, 0, 0.2, 0.3, 0.0};
  PushSpec p;
  p.point_body = {-0.05, -0.02};
  p.direction_body = {1, 0};
  p.height_m = s.slider.com_height_m;
  p.force_N = 2.6;
  p.amplitude_N = 2.0;
  p.period_s = 0.2;
  s.pushes.push_back(p);
  s.duration_s = 1.0;
  return s;
}

/// Pushed low (below the CM): tilting moments couple the equations (model.md, (*)).
inline Scene TiltingPush() {
  Scene s = PushedSlider();
  s.pushes[0].height_m = 0.005;
  s.pushes[0].direction_body = Eigen::Vector2d(1, 0.3).normalized();
  return s;
}

/// Anisotropic friction, b = e_o / e_t = 1.6, with spin.
inline Scene Anisotropic() {
  Scene s = FreeSlideWithSpin();
  s.friction = {0.25, 1.0, 1.6, 0.04};
  s.duration_s = 0.35;
  return s;
}

/// Pure translation (no spin, push through the CM): c cannot be identified.
inline Scene PureTranslation() {
  Scene s = BaseScene();
  s.slider.com_height_m = 0.0;
  s.initial = {0, 0, 0, 0.3, 0.2, 0.0};
  PushSpec p;
  p.point_body = {-0.05, 0.0};
  p.direction_body = {1, 0};
  p.height_m = 0.0;
  p.force_N = 3.2;
  p.amplitude_N = 1.0;
  p.period_s = 0.25;
  s.pushes.push_back(p);
  s.duration_s = 0.8;
  return s;
}

/// Motion along body and world x only: neither b nor c can be identified.
inline Scene AlongOneAxis() {
  Scene s = PureTranslation();
  s.initial.vy = 0.0;
  return s;
}

inline Trajectory SimulateOrFail(const Scene& scene) {
  const SimulationResult r = Simulate(scene);
  EXPECT_TRUE(r.summary.ok()) << r.summary.message;
  return r.trajectory;
}

}  // namespace slideid::testing

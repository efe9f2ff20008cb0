#pragma once
// Random but realistic steps, shared by the step tests and the step benchmark: log-uniform
// sizes, q_z > 0, tilting moments, pushes up to 1.5 times the weight. Seeded.

#include <cmath>
#include <random>

#include "forward_model/planar_state.h"
#include "forward_model/slider.h"

namespace slideid::testing {

/// One step to solve: everything SolveStep takes.
struct Case {
  SliderProperties slider;
  FrictionParameters friction;
  PlanarState state;
  AppliedWrench applied;
  double dt_s = 0.01;  ///< [s]
};

class CaseGenerator {
 public:
  explicit CaseGenerator(unsigned seed) : rng_(seed) {}
  double LogUniform(double lo, double hi) {
    return std::exp(std::uniform_real_distribution<double>(std::log(lo), std::log(hi))(rng_));
  }
  double Uniform(double lo, double hi) {
    return std::uniform_real_distribution<double>(lo, hi)(rng_);
  }
  /// The general case: every term of the step's equations present.
  Case General() {
    Case c;
    const double size = LogUniform(0.02, 0.3);  // patch half-size scale [m]
    c.slider.mass_kg = LogUniform(0.05, 20);
    c.slider.inertia_kgm2 = c.slider.mass_kg * size * size * Uniform(0.1, 0.7);
    c.slider.com_height_m = size * Uniform(0.0, 1.0);
    c.slider.gravity_mps2 = 9.81;
    c.friction = {LogUniform(0.05, 1.0), LogUniform(0.5, 2.0), LogUniform(0.5, 2.0),
                  size * LogUniform(0.1, 1.0)};
    const double speed = LogUniform(0.01, 2.0);
    c.state = {Uniform(-1, 1), Uniform(-1, 1), Uniform(-3, 3), speed * Uniform(-1, 1),
               speed * Uniform(-1, 1), speed / size * Uniform(-1, 1)};
    const double weight = c.slider.mass_kg * c.slider.gravity_mps2;
    const double push = weight * Uniform(0, 1.5);
    const double angle = Uniform(-M_PI, M_PI);
    c.applied.fx = push * std::cos(angle);
    c.applied.fy = push * std::sin(angle);
    c.applied.fz = weight * Uniform(-0.3, 0.3);
    c.applied.tx = weight * size * Uniform(-0.2, 0.2);
    c.applied.ty = weight * size * Uniform(-0.2, 0.2);
    c.applied.tz = weight * size * Uniform(-0.5, 0.5);
    c.dt_s = LogUniform(1e-3, 2e-2);
    return c;
  }

 private:
  std::mt19937_64 rng_;
};

}  // namespace slideid::testing

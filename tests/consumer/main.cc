// A program outside slideid, built against its installed package: simulates a slider with
// known friction, writes its log and reads it back (slideid::io), identifies it
// (slideid::estimator) and checks the estimates against the truth. Prints the package's
// version, which the test compares with the installed tools' --version.

#include <cmath>
#include <cstdio>
#include <sstream>

#include "estimator/identify.h"
#include "forward_model/simulator.h"
#include "io/push_log.h"

int main() {
  using namespace slideid;
  // A 10 cm square box sliding freely with spin: a, b and c are all identifiable.
  Scene scene;
  scene.source = "consumer";
  scene.slider = {1.0, 1.0 * (0.1 * 0.1 + 0.1 * 0.1) / 12, 0.03, 9.81};
  scene.friction = FrictionParameters{0.3, 1.0, 1.4, 0.03};
  scene.patch = ContactPatch::Rectangle(0.1, 0.1);
  scene.initial = {0, 0, 0, 1.2, 0.8, 12.0};
  scene.dt_s = 0.01;
  scene.duration_s = 0.4;
  const SimulationResult simulated = Simulate(scene);
  if (!simulated.summary.ok()) {
    std::printf("simulation failed: %s\n", simulated.summary.message.c_str());
    return 1;
  }
  std::stringstream text;
  WritePushLog(simulated.trajectory, text);
  const Trajectory log = ParsePushLog(text.str(), "consumer.csv");

  const EstimateResult result = Identify(log, IdentifyOptions{});
  const ReducedFriction truth = scene.friction.reduced();
  const double expected[3] = {truth.a, truth.b, truth.c};
  // A noiseless log of the model itself: the fit must land on the truth, far inside 1e-4.
  constexpr double kRelativeTolerance = 1e-4;
  int failures = result.converged ? 0 : 1;
  for (int i = 0; i < 3; ++i) {
    const ParameterEstimate& p = result.parameters[i];
    const double error = std::abs(p.value / expected[i] - 1);
    std::printf("%s = %.6g (truth %.6g)\n", ParameterName(i), p.value, expected[i]);
    if (!p.identifiable || !(error < kRelativeTolerance)) ++failures;
  }
  std::printf("slideid %s: %s\n", PACKAGE_VERSION, failures == 0 ? "ok" : "FAILED");
  return failures == 0 ? 0 : 1;
}

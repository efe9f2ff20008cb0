// libFuzzer target: the scene reader on arbitrary text (ParseScene, the same code as
// LoadScene on a file). SceneError and std::invalid_argument are the expected answers to
// bad input; any other exception, a sanitizer report, or an accepted scene with a value
// outside its documented range is a crash.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include "io/scene_file.h"

namespace {

void Require(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "fuzz_scene: invariant broken: %s\n", what);
    std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  slideid::Scene scene;
  try {
    scene = slideid::ParseScene(text, "fuzz.ini");
  } catch (const slideid::SceneError&) {
    return 0;
  } catch (const std::invalid_argument&) {
    return 0;
  }
  const auto& s = scene.slider;
  Require(std::isfinite(s.mass_kg) && s.mass_kg > 0, "mass > 0");
  Require(std::isfinite(s.inertia_kgm2) && s.inertia_kgm2 > 0, "inertia > 0");
  Require(std::isfinite(s.com_height_m) && s.com_height_m >= 0, "com_height >= 0");
  Require(std::isfinite(s.gravity_mps2) && s.gravity_mps2 > 0, "gravity > 0");
  Require(std::isfinite(scene.dt_s) && scene.dt_s > 0, "dt > 0");
  Require(std::isfinite(scene.duration_s) && scene.duration_s > 0, "duration > 0");
  const auto& f = scene.friction.paper();
  Require(
      std::isfinite(f.mu) && std::isfinite(f.e_t) && std::isfinite(f.e_o) && std::isfinite(f.e_r),
      "finite friction");
  for (const slideid::PushSpec& p : scene.pushes) {
    Require(std::isfinite(p.force_n) && std::isfinite(p.amplitude_n) && std::isfinite(p.period_s) &&
                std::isfinite(p.height_m) && p.point_body.allFinite() &&
                p.direction_body.allFinite(),
            "finite push");
  }
  return 0;
}

#include "io/push_advice_report.h"

#include <cmath>
#include <nlohmann/json.hpp>
#include <sstream>

#include "forward_model/constants.h"
#include "forward_model/number_format.h"
#include "io/internal/json_line.h"
#include "io/result_json.h"

namespace slideid {
namespace {

using Json = nlohmann::ordered_json;

const char* const kPrefix = "advise-push: result JSON: ";

[[noreturn]] void Fail(const std::string& path, const std::string& what) {
  throw ResultJsonError(kPrefix + (path.empty() ? what : path + ": " + what));
}

const nlohmann::json& Member(const nlohmann::json& object, const std::string& path,
                             const std::string& key) {
  if (!object.is_object()) Fail(path, "expected an object");
  const auto it = object.find(key);
  if (it == object.end()) Fail(path, "no \"" + key + "\"");
  return *it;
}

/// A number, or NaN for null.
double Number(const nlohmann::json& j, const std::string& path) {
  if (j.is_null()) return std::nan("");
  if (!j.is_number()) Fail(path, "expected a number or null, got " + json_line::Brief(j));
  return j.get<double>();
}

Json Finite(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }

Json Pair(const Eigen::Vector2d& v) { return Json::array({Finite(v.x()), Finite(v.y())}); }

}  // namespace

AdviceResultInput ParseAdviceResult(const std::string& text) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {  // a syntax error, or a number overflow
    Fail("", std::string("not JSON: ") + e.what());
  }
  if (!j.is_object()) Fail("", "expected an object (identify --json), got " + json_line::Brief(j));
  AdviceResultInput in;
  for (int i = 0; i < 3; ++i) {
    const std::string path = std::string("/") + ParameterName(i);
    const nlohmann::json& p = Member(j, "", ParameterName(i));
    ParameterEstimate& e = in.result.parameters[i];
    const nlohmann::json& identifiable = Member(p, path, "identifiable");
    if (!identifiable.is_boolean()) Fail(path + "/identifiable", "expected true or false");
    e.identifiable = identifiable.get<bool>();
    e.verdict = e.identifiable ? Verdict::kOk : Verdict::kNotIdentifiable;
    if (e.identifiable) {
      e.value = Number(Member(p, path, "value"), path + "/value");
      e.stderr_value = Number(Member(p, path, "stderr"), path + "/stderr");
      if (!(e.value > 0 && std::isfinite(e.value))) {
        Fail(path + "/value", "an identifiable parameter needs a positive value, got " +
                                  json_line::Brief(Member(p, path, "value")));
      }
      if (!(e.stderr_value > 0 && std::isfinite(e.stderr_value))) {
        Fail(path + "/stderr",
             "an identifiable parameter needs a positive, finite standard "
             "error, got " +
                 json_line::Brief(Member(p, path, "stderr")));
      }
    } else if (p.contains("held_at")) {
      e.held_at = Number(p["held_at"], path + "/held_at");
    }
  }
  if (j.contains("residual_rms")) {
    const double rms = Number(j["residual_rms"], "/residual_rms");
    if (std::isfinite(rms)) {
      if (!(rms > 0))
        Fail("/residual_rms",
             "expected a positive number, got " + json_line::Brief(j["residual_rms"]));
      in.pose_noise_m = rms / std::sqrt(3.0);
    }
  }
  if (j.contains("mu_pusher") && !j["mu_pusher"].is_null()) {
    const nlohmann::json& m = j["mu_pusher"];
    if (m.is_object() && m.contains("value")) {
      const double mu = Number(m["value"], "/mu_pusher/value");
      if (std::isfinite(mu)) {
        if (!(mu >= 0))
          Fail("/mu_pusher/value", "expected a number >= 0, got " + json_line::Brief(m["value"]));
        in.mu_pusher = mu;
      }
    } else if (!m.is_object()) {
      Fail("/mu_pusher", "expected an object or null, got " + json_line::Brief(m));
    }
  }
  return in;
}

std::string FormatAdviceJson(const PushAdvice& advice, const SliderProperties& slider,
                             const ContactPatch& patch, const PushAdviceOptions& options, int top) {
  Json j;
  j["criterion"] = ToString(advice.criterion);
  j["pose_noise_m"] = Finite(advice.pose_noise_m);
  j["mu_pusher"] = Finite(options.candidates.mu_pusher);
  Json known = Json::object();
  const double values[3] = {advice.knowledge.estimate.a, advice.knowledge.estimate.b,
                            advice.knowledge.estimate.c};
  for (int i = 0; i < 3; ++i) {
    known[ParameterName(i)] = Json{{"value", Finite(values[i])},
                                   {"relative_stderr", Finite(advice.relative_stderr_now[i])},
                                   {"from", advice.knowledge.from[i]}};
  }
  j["known"] = known;
  int failed = 0;
  for (const CandidateAdvice& c : advice.ranking) failed += !c.simulated;
  j["candidates"] = static_cast<int>(advice.ranking.size());
  j["failed"] = failed;
  Json ranking = Json::array();
  const int n = static_cast<int>(advice.ranking.size());
  const int shown = top <= 0 ? n : std::min(top, n);
  for (int r = 0; r < shown; ++r) {
    const CandidateAdvice& c = advice.ranking[r];
    const Scene scene = PushScene(slider, advice.knowledge.estimate, patch, c.push,
                                  options.candidates, 1.0 / options.log_rate_hz);
    Json info = Json::array();
    for (int a = 0; a < 3; ++a) {
      info.push_back(Json::array({Finite(c.information_log(a, 0)), Finite(c.information_log(a, 1)),
                                  Finite(c.information_log(a, 2))}));
    }
    Json rel = Json::array(), abs = Json::array();
    for (int i = 0; i < 3; ++i) {
      rel.push_back(Finite(c.relative_stderr_after[i]));
      abs.push_back(Finite(c.relative_stderr_after[i] * values[i]));
    }
    ranking.push_back(
        Json{{"rank", r + 1},
             {"outline_fraction", Finite(c.push.outline_fraction)},
             {"contact_m", Pair(c.push.contact_body)},
             {"direction", Pair(c.push.direction_body)},
             {"angle_from_normal_deg", Finite(c.push.angle_from_normal_rad * kRadToDeg)},
             {"length_m", Finite(c.push.length_m)},
             {"tip_start_m", Pair(scene.pusher->path.points_m().front())},
             {"tip_end_m", Pair(scene.pusher->path.points_m().back())},
             {"score", Finite(c.score)},
             {"relative_stderr_after", rel},
             {"stderr_after", abs},
             {"information_log", info},
             {"moved_m", Finite(c.moved_m)},
             {"turned_deg", Finite(c.turned_rad * kRadToDeg)},
             {"simulated", c.simulated},
             {"failure", c.failure}});
  }
  j["ranking"] = ranking;
  return j.dump();
}

std::string FormatAdviceText(const PushAdvice& advice, const PushAdviceOptions& options, int top) {
  std::ostringstream out;
  const double values[3] = {advice.knowledge.estimate.a, advice.knowledge.estimate.b,
                            advice.knowledge.estimate.c};
  out << "known now (" << ToString(advice.criterion) << " ranking, pose noise "
      << Printf("%.3g", advice.pose_noise_m * 1e3) << " mm, mu_p "
      << Printf("%.3g", options.candidates.mu_pusher) << "):\n";
  for (int i = 0; i < 3; ++i) {
    out << Printf("  %-13s %10.4g  relative std. error %s  (%s)\n", ParameterName(i), values[i],
                  std::isfinite(advice.relative_stderr_now[i])
                      ? Printf("%.3g%%", 100 * advice.relative_stderr_now[i])
                      : std::string("unknown"),
                  advice.knowledge.from[i]);
  }
  int failed = 0;
  for (const CandidateAdvice& c : advice.ranking) failed += !c.simulated;
  out << advice.ranking.size() << " candidate pushes";
  if (failed) out << " (" << failed << " failed to simulate: ranked last)";
  out << "; expected relative standard errors after each:\n";
  out << Printf("%4s  %8s  %-19s  %9s  %6s  %9s  %9s  %9s  %s\n", "rank", "outline", "contact (mm)",
                "angle", "length", "a", "b", "c", "slider moves");
  const int n = static_cast<int>(advice.ranking.size());
  const int shown = top <= 0 ? n : std::min(top, n);
  const auto pct = [](double v) {
    return std::isfinite(v) ? Printf("%.3g%%", 100 * v) : std::string("unknown");
  };
  for (int r = 0; r < shown; ++r) {
    const CandidateAdvice& c = advice.ranking[r];
    out << Printf(
        "%4d  %8.3f  %-19s  %+7.1f d  %3.0f mm  %9s  %9s  %9s  ", r + 1, c.push.outline_fraction,
        Printf("(%.1f, %.1f)", c.push.contact_body.x() * 1e3, c.push.contact_body.y() * 1e3),
        c.push.angle_from_normal_rad * kRadToDeg, c.push.length_m * 1e3,
        pct(c.relative_stderr_after[0]), pct(c.relative_stderr_after[1]),
        pct(c.relative_stderr_after[2]));
    if (c.simulated) {
      out << Printf("%.0f mm, %.1f deg", c.moved_m * 1e3, c.turned_rad * kRadToDeg);
    } else {
      out << "failed: " << c.failure;
    }
    out << "\n";
  }
  out << "(outline: fraction of the outline's length from its first vertex, counter-clockwise;"
         " angle: of the push from the inward normal, within the friction cone of mu_p;"
         " length: tip travel after touching)\n";
  return out.str();
}

}  // namespace slideid

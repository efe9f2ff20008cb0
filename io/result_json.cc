#include "io/result_json.h"

#include <climits>
#include <cmath>
#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>

#include "io/internal/json_line.h"

namespace slideid {
namespace {

using json_line::Json;
using json_line::NumberOrNull;
using json_line::Print;

const char* const kPrefix = "identify JSON: ";
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// A value quoted in a message is cut to this many characters.
constexpr std::size_t kMaxQuoted = 40;

// ---- writing ----

Json ParameterJson(const ParameterEstimate& p) {
  const bool id = p.identifiable;
  Json j = Json::object();
  j["value"] = id ? NumberOrNull(p.value) : Json(nullptr);
  j["stderr"] = id ? NumberOrNull(p.stderr_value) : Json(nullptr);
  j["ci95"] = Json::array(
      {id ? NumberOrNull(p.ci95_lo) : Json(nullptr), id ? NumberOrNull(p.ci95_hi) : Json(nullptr)});
  j["interval_quantile"] = id ? NumberOrNull(p.interval_quantile) : Json(nullptr);
  j["identifiable"] = id;
  j["verdict"] = ToString(p.verdict);
  j["reason"] = p.reason;
  j["held_at"] = id ? Json(nullptr) : NumberOrNull(p.held_at);
  j["note"] = p.note;
  return j;
}

Json NuisanceJson(const NuisanceEstimate& n) {
  const bool id = n.identifiable;
  Json j = Json::object();
  j["log"] = n.log;
  j["value"] = id ? NumberOrNull(n.value) : Json(nullptr);
  j["stderr"] = id ? NumberOrNull(n.stderr_value) : Json(nullptr);
  j["ci95"] = Json::array(
      {id ? NumberOrNull(n.ci95_lo) : Json(nullptr), id ? NumberOrNull(n.ci95_hi) : Json(nullptr)});
  j["identifiable"] = id;
  j["verdict"] = ToString(n.verdict);
  j["reason"] = n.reason;
  j["held_at"] = id ? Json(nullptr) : NumberOrNull(n.held_at);
  return j;
}

Json LogJson(const LogResult& log) {
  Json j = Json::object();
  j["name"] = log.name;
  j["skipped"] = log.skipped;
  j["skip_reason"] = log.skip_reason;
  j["rows"] = log.rows;
  j["steps_used"] = log.steps_used;
  j["status"] = ToString(log.status);
  j["message"] = log.message;
  for (int i = 0; i < 3; ++i) j[ParameterName(i)] = ParameterJson(log.parameters[i]);
  return j;
}

Json HeterogeneityJson(const Heterogeneity& h) {
  Json j = Json::object();
  j["tested"] = h.tested;
  j["logs"] = h.logs;
  j["q"] = NumberOrNull(h.q);
  j["p_value"] = NumberOrNull(h.p_value);
  j["i2"] = NumberOrNull(h.i2);
  j["tau_log"] = NumberOrNull(h.tau_log);
  j["consistent"] = h.consistent;
  return j;
}

// ---- reading: typed access whose errors name the JSON path ----

[[noreturn]] void Fail(const std::string& path, const std::string& what) {
  throw ResultJsonError(kPrefix + (path.empty() ? what : path + ": " + what));
}

// Never the whole dump: a file may nest arrays deeper than dump's recursion can go.
std::string Quoted(const Json& j) { return json_line::Brief(j, kMaxQuoted); }

Json Parse(const std::string& text) {
  try {
    return Json::parse(text);
  } catch (const Json::exception& e) {
    // "[json.exception.parse_error.101] parse error at line 1, column 5: ...", or
    // "[json.exception.out_of_range.406] number overflow parsing '1e999'"
    const std::string what = e.what();
    const auto tag_end = what.find("] ");
    Fail("", tag_end == std::string::npos ? what : what.substr(tag_end + 2));
  }
}

const Json& Member(const Json& object, const std::string& path, const std::string& key) {
  const auto it = object.find(key);
  if (it == object.end()) Fail(path, "no \"" + key + "\"");
  return *it;
}

const Json& Object(const Json& j, const std::string& path) {
  if (!j.is_object()) Fail(path, "expected an object, got " + Quoted(j));
  return j;
}

double NumberOrNaN(const Json& j, const std::string& path) {
  if (j.is_null()) return kNaN;
  if (!j.is_number()) Fail(path, "expected a number or null, got " + Quoted(j));
  return j.get<double>();
}

int Count(const Json& j, const std::string& path) {
  // nlohmann reads a non-negative integer as unsigned, a negative one as signed.
  if (!j.is_number_unsigned() || j.get<std::uint64_t>() > INT_MAX) {
    Fail(path, "expected an integer from 0 to " + std::to_string(INT_MAX) + ", got " + Quoted(j));
  }
  return static_cast<int>(j.get<std::uint64_t>());
}

bool Boolean(const Json& j, const std::string& path) {
  if (!j.is_boolean()) Fail(path, "expected true or false, got " + Quoted(j));
  return j.get<bool>();
}

std::string Text(const Json& j, const std::string& path) {
  if (!j.is_string()) Fail(path, "expected a string, got " + Quoted(j));
  return j.get<std::string>();
}

/// Member `key` of the object at `path`, read by `read` with its own path in messages.
template <typename Read>
auto Field(const Json& object, const std::string& path, const std::string& key, Read read) {
  return read(Member(object, path, key), path + "/" + key);
}

template <typename Enum, size_t N>
Enum Named(const Json& j, const std::string& path, const Enum (&choices)[N]) {
  const std::string name = Text(j, path);
  std::string all;
  for (Enum e : choices) {
    if (name == ToString(e)) return e;
    all += (all.empty() ? "" : ", ") + std::string(ToString(e));
  }
  Fail(path, "unknown value '" + name + "' (" + all + ")");
}

constexpr Verdict kVerdicts[] = {Verdict::kOk, Verdict::kSuspect, Verdict::kNotIdentifiable};
constexpr TerminationStatus kStatuses[] = {
    TerminationStatus::kConverged, TerminationStatus::kConvergedWithCaveats,
    TerminationStatus::kNoConvergence, TerminationStatus::kTooLittleExcitation};

Verdict ReadVerdict(const Json& j, const std::string& path) { return Named(j, path, kVerdicts); }
TerminationStatus ReadStatus(const Json& j, const std::string& path) {
  return Named(j, path, kStatuses);
}

void ReadInterval(const Json& j, const std::string& path, double* lo, double* hi) {
  const Json& ci = Member(j, path, "ci95");
  if (!ci.is_array() || ci.size() != 2)
    Fail(path + "/ci95", "expected [lo, hi], got " + Quoted(ci));
  *lo = NumberOrNaN(ci[0], path + "/ci95/0");
  *hi = NumberOrNaN(ci[1], path + "/ci95/1");
}

ParameterEstimate ReadParameter(const Json& j, const std::string& path);

ParameterEstimate ReadParameterAt(const Json& parent, const std::string& parent_path, int index) {
  const std::string path = parent_path + "/" + ParameterName(index);
  return ReadParameter(Object(Member(parent, parent_path, ParameterName(index)), path), path);
}

ParameterEstimate ReadParameter(const Json& j, const std::string& path) {
  ParameterEstimate p;
  p.value = Field(j, path, "value", NumberOrNaN);
  p.stderr_value = Field(j, path, "stderr", NumberOrNaN);
  ReadInterval(j, path, &p.ci95_lo, &p.ci95_hi);
  // Optional: results written before it was (issue 21) read as z-based intervals.
  if (j.contains("interval_quantile")) {
    const std::string at = path + "/interval_quantile";
    const double q = NumberOrNaN(j.at("interval_quantile"), at);
    if (std::isfinite(q) && !(q >= kZ95))
      Fail(at, "expected a quantile of at least 1.96, got " + Quoted(j.at("interval_quantile")));
    if (std::isfinite(q)) p.interval_quantile = q;
  }
  p.identifiable = Field(j, path, "identifiable", Boolean);
  p.verdict = Field(j, path, "verdict", ReadVerdict);
  p.reason = Field(j, path, "reason", Text);
  p.held_at = Field(j, path, "held_at", NumberOrNaN);
  p.note = Field(j, path, "note", Text);
  return p;
}

const Json& Array(const Json& j, const std::string& path) {
  if (!j.is_array()) Fail(path, "expected an array, got " + Quoted(j));
  return j;
}

NuisanceEstimate ReadNuisance(const Json& j, const std::string& path, const std::string& name) {
  Object(j, path);
  NuisanceEstimate n;
  n.name = name;
  n.log = Field(j, path, "log", Text);
  n.value = Field(j, path, "value", NumberOrNaN);
  n.stderr_value = Field(j, path, "stderr", NumberOrNaN);
  ReadInterval(j, path, &n.ci95_lo, &n.ci95_hi);
  n.identifiable = Field(j, path, "identifiable", Boolean);
  n.verdict = Field(j, path, "verdict", ReadVerdict);
  n.reason = Field(j, path, "reason", Text);
  n.held_at = Field(j, path, "held_at", NumberOrNaN);
  return n;
}

LogResult ReadLog(const Json& j, const std::string& path) {
  Object(j, path);
  LogResult log;
  log.name = Field(j, path, "name", Text);
  log.skipped = Field(j, path, "skipped", Boolean);
  log.skip_reason = Field(j, path, "skip_reason", Text);
  log.rows = Field(j, path, "rows", Count);
  log.steps_used = Field(j, path, "steps_used", Count);
  log.status = Field(j, path, "status", ReadStatus);
  log.message = Field(j, path, "message", Text);
  for (int i = 0; i < 3; ++i) log.parameters[i] = ReadParameterAt(j, path, i);
  return log;
}

Heterogeneity ReadHeterogeneity(const Json& j, const std::string& path) {
  Object(j, path);
  Heterogeneity h;
  h.tested = Field(j, path, "tested", Boolean);
  h.logs = Field(j, path, "logs", Count);
  h.q = Field(j, path, "q", NumberOrNaN);
  h.p_value = Field(j, path, "p_value", NumberOrNaN);
  h.i2 = Field(j, path, "i2", NumberOrNaN);
  h.tau_log = Field(j, path, "tau_log", NumberOrNaN);
  h.consistent = Field(j, path, "consistent", Boolean);
  return h;
}

ParameterEstimate ReadParameter(const Json& root, int index) {
  return ReadParameterAt(root, "", index);
}

EstimatorMethod ReadMethod(const Json& root) {
  const std::string name = Field(root, "", "method", Text);
  for (EstimatorMethod m : {EstimatorMethod::kClosedForm, EstimatorMethod::kEquationError,
                            EstimatorMethod::kTrajectory, EstimatorMethod::kQuasiStatic}) {
    if (name == ToString(m)) return m;
  }
  Fail("/method",
       "unknown method '" + name + "' (closed-form, equation-error, trajectory, quasi-static)");
}

/// The result as FormatJson writes it, before printing.
Json ResultDoc(const EstimateResult& r) {
  Json doc = Json::object();
  for (int i = 0; i < 3; ++i) doc[ParameterName(i)] = ParameterJson(r.parameters[i]);
  int excluded = 0;
  Json reasons = Json::object();
  for (const auto& [reason, count] : r.steps_excluded) {
    excluded += count;
    reasons[reason] = reasons.value(reason, 0) + count;  // one key per reason
  }
  doc["method"] = ToString(r.method);
  doc["status"] = ToString(r.status);
  doc["steps_used"] = r.steps_used;
  doc["steps_total"] = r.steps_total;
  doc["steps_excluded"] = excluded;
  doc["steps_excluded_by_reason"] = reasons;
  doc["seconds"] = NumberOrNull(r.seconds);
  doc["iterations"] = r.iterations;
  doc["final_cost"] = NumberOrNull(r.final_cost);
  doc["converged"] = r.converged;
  doc["message"] = r.message;
  doc["log_noise"] = NumberOrNull(r.log_noise);
  doc["residual_rms"] = NumberOrNull(r.residual_rms);
  Json nuisance = Json::object();
  for (const NuisanceEstimate& n : r.nuisance) {
    if (!nuisance.contains(n.name)) nuisance[n.name] = Json::array();
    nuisance[n.name].push_back(NuisanceJson(n));
  }
  doc["nuisance"] = nuisance;
  doc["logs"] = Json::array();
  for (const LogResult& log : r.logs) doc["logs"].push_back(LogJson(log));
  Json heterogeneity = Json::object();
  for (int i = 0; i < 3; ++i)
    heterogeneity[ParameterName(i)] = HeterogeneityJson(r.heterogeneity[i]);
  doc["heterogeneity"] = heterogeneity;
  if (r.mu_pusher_examined) {
    Json mu = ParameterJson(r.mu_pusher);
    mu["lower_bound"] = NumberOrNull(r.mu_pusher_lower_bound);
    doc["mu_pusher"] = mu;
  } else {
    doc["mu_pusher"] = nullptr;
  }
  return doc;
}

}  // namespace

std::string FormatJson(const EstimateResult& r) {
  std::string out;
  Print(ResultDoc(r), &out);
  return out;
}

std::string FormatBatchLine(const std::string& file, const EstimateResult* result,
                            const std::string& error, const std::vector<std::string>& warnings,
                            const std::string& sha256) {
  if (error.empty() && result == nullptr) {
    throw std::invalid_argument("FormatBatchLine: " + file + ": neither a result nor an error");
  }
  Json doc = Json::object();
  doc["file"] = file;
  if (!sha256.empty()) doc["sha256"] = sha256;
  doc["ok"] = error.empty();
  if (error.empty()) {
    const Json body = ResultDoc(*result);
    for (auto it = body.begin(); it != body.end(); ++it) doc[it.key()] = it.value();
    doc["warnings"] = warnings;
  } else {
    doc["error"] = error;
    if (result != nullptr) doc["result"] = ResultDoc(*result);
  }
  std::string out;
  Print(doc, &out);
  return out;
}

std::optional<BatchLineKey> ParseBatchLineKey(std::string_view line) {
  const Json doc = Json::parse(line, nullptr, /*allow_exceptions=*/false);
  if (!doc.is_object()) return std::nullopt;
  const auto file = doc.find("file");
  const auto ok = doc.find("ok");
  if (file == doc.end() || !file->is_string() || ok == doc.end() || !ok->is_boolean()) {
    return std::nullopt;
  }
  BatchLineKey key;
  key.file = file->get<std::string>();
  key.ok = ok->get<bool>();
  if (const auto hash = doc.find("sha256"); hash != doc.end() && hash->is_string()) {
    key.sha256 = hash->get<std::string>();
  }
  return key;
}

EstimateResult ParseResultJson(const std::string& json) {
  const Json parsed = Parse(json);  // not copied: a copy recurses as deep as the nesting
  const Json& root = Object(parsed, "");
  EstimateResult r;
  for (int i = 0; i < 3; ++i) r.parameters[i] = ReadParameter(root, i);
  r.method = ReadMethod(root);
  r.status = Field(root, "", "status", ReadStatus);
  r.steps_used = Field(root, "", "steps_used", Count);
  r.steps_total = Field(root, "", "steps_total", Count);
  const int excluded = Field(root, "", "steps_excluded", Count);
  const Json& reasons =
      Object(Member(root, "", "steps_excluded_by_reason"), "/steps_excluded_by_reason");
  long long sum = 0;
  for (auto it = reasons.begin(); it != reasons.end(); ++it) {
    const int count = Count(it.value(), "/steps_excluded_by_reason/" + it.key());
    r.steps_excluded.emplace_back(it.key(), count);
    sum += count;
  }
  if (sum != excluded) {
    Fail("/steps_excluded", std::to_string(excluded) + " is not the sum of " +
                                "steps_excluded_by_reason (" + std::to_string(sum) + ")");
  }
  r.seconds = Field(root, "", "seconds", NumberOrNaN);
  r.iterations = Field(root, "", "iterations", Count);
  r.final_cost = Field(root, "", "final_cost", NumberOrNaN);
  r.converged = Field(root, "", "converged", Boolean);
  r.message = Field(root, "", "message", Text);
  r.log_noise = Field(root, "", "log_noise", NumberOrNaN);
  r.residual_rms = Field(root, "", "residual_rms", NumberOrNaN);
  const Json& nuisance = Object(Member(root, "", "nuisance"), "/nuisance");
  for (auto it = nuisance.begin(); it != nuisance.end(); ++it) {
    const std::string path = "/nuisance/" + it.key();
    const Json& entries = Array(it.value(), path);
    for (size_t k = 0; k < entries.size(); ++k) {
      r.nuisance.push_back(ReadNuisance(entries[k], path + "/" + std::to_string(k), it.key()));
    }
  }
  const Json& logs = Array(Member(root, "", "logs"), "/logs");
  for (size_t k = 0; k < logs.size(); ++k) {
    r.logs.push_back(ReadLog(logs[k], "/logs/" + std::to_string(k)));
  }
  const Json& heterogeneity = Object(Member(root, "", "heterogeneity"), "/heterogeneity");
  for (int i = 0; i < 3; ++i) {
    r.heterogeneity[i] =
        ReadHeterogeneity(Member(heterogeneity, "/heterogeneity", ParameterName(i)),
                          std::string("/heterogeneity/") + ParameterName(i));
  }
  // Optional: results written before mu_p was estimated have no such key.
  if (const auto it = root.find("mu_pusher"); it != root.end() && !it->is_null()) {
    const Json& mu = Object(*it, "/mu_pusher");
    r.mu_pusher_examined = true;
    r.mu_pusher = ReadParameter(mu, "/mu_pusher");
    r.mu_pusher_lower_bound = Field(mu, "/mu_pusher", "lower_bound", NumberOrNaN);
  }
  return r;
}

ReducedFriction ParseIdentifyJson(const std::string& json) {
  const Json parsed = Parse(json);  // not copied: a copy recurses as deep as the nesting
  const Json& root = Object(parsed, "");
  const auto value_of = [&](int index) {
    const std::string name = ParameterName(index);
    const Json& p = Object(Member(root, "", name), "/" + name);
    for (const char* field : {"value", "held_at"}) {
      const auto it = p.find(field);
      if (it == p.end()) continue;
      const double v = NumberOrNaN(*it, "/" + name + "/" + field);
      if (std::isfinite(v) && v > 0) return v;
    }
    Fail("", "\"" + name + "\" has neither a value nor a held_at value");
  };
  return {value_of(kA), value_of(kB), value_of(kC)};
}

}  // namespace slideid

// libFuzzer target: the wrench-twist CSV reader on arbitrary bytes (ParseWrenchTwistCsv,
// the same code as ReadWrenchTwistCsv on a file), then the quasi-static fit on what it
// accepts. LogError is the expected answer to bad text; an accepted file has rows whose
// pairs are finite, with non-zero wrench and twist and a positive normal force, and it
// survives a write/read round trip unchanged. The fit may only throw std::invalid_argument
// (too few pairs); it must return, and an estimate it calls identifiable is finite.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>

#include "estimator/quasi_static_fit.h"
#include "io/wrench_twist_csv.h"

namespace {

using namespace slideid;

/// The fit runs on files with at most this many rows: it costs ~1 ms for tens of pairs,
/// and larger files exercise the reader, not the fit.
constexpr std::size_t kMaxFittedRows = 64;

void Require(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "fuzz_wrench_twist: invariant broken: %s\n", what);
    std::abort();
  }
}

void CheckAccepted(const WrenchTwistData& data) {
  Require(!data.rows.empty(), "an accepted file has a row");
  Require(data.mass_kg > 0.0 && std::isfinite(data.WeightN()), "the weight is finite");
  for (const WrenchTwistRow& row : data.rows) {
    const WrenchTwistPair& p = row.pair;
    for (double v : {p.fx, p.fy, p.fz, p.mz, p.vx, p.vy, p.wz}) {
      Require(std::isfinite(v), "pairs are finite");
    }
    Require(p.fx != 0.0 || p.fy != 0.0 || p.mz != 0.0, "the wrench is not zero");
    Require(p.vx != 0.0 || p.vy != 0.0 || p.wz != 0.0, "the twist is not zero");
    Require(data.WeightN() - p.fz > 0.0, "the normal force is positive");
  }
}

void CheckRoundTrip(const WrenchTwistData& data) {
  std::ostringstream out;
  try {
    WriteWrenchTwistCsv(data, out);
  } catch (const std::invalid_argument&) {
    return;  // metadata the writer refuses (documented), not a reader bug
  }
  const WrenchTwistData back = ParseWrenchTwistCsv(out.str(), "fuzz_round_trip.csv");
  Require(back.rows.size() == data.rows.size(), "round trip keeps the rows");
  for (std::size_t i = 0; i < data.rows.size(); ++i) {
    const WrenchTwistPair &a = data.rows[i].pair, &b = back.rows[i].pair;
    Require(a.fx == b.fx && a.mz == b.mz && a.wz == b.wz, "round trip keeps the pairs");
  }
}

void CheckFit(const WrenchTwistData& data) {
  if (data.rows.size() > kMaxFittedRows) return;
  EstimateResult result;
  try {
    result = EstimateQuasiStatic(data.Pairs(), QuasiStaticOptionsFor(data, IdentifyOptions{}));
  } catch (const std::invalid_argument&) {
    return;
  }
  for (const ParameterEstimate& p : result.parameters) {
    if (p.identifiable && result.converged) {
      Require(std::isfinite(p.value) && p.value > 0.0, "an identifiable estimate is finite");
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  WrenchTwistData pairs;
  try {
    pairs = ParseWrenchTwistCsv(text, "fuzz.csv");
  } catch (const LogError&) {
    return 0;
  }
  CheckAccepted(pairs);
  CheckRoundTrip(pairs);
  CheckFit(pairs);
  return 0;
}

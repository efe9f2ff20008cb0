// Which push next (issue 21): how many pushes bring every one of a, b, c under a 2% relative
// standard error when each push follows advise-push's advice, against make-dataset's random
// pusher pushes, on sliders drawn widely (fixtures/push_race.h). docs/online.md, "Which
// push next", has the figures.
//
//   advise_push_benchmark [--sliders 50] [--seed 1] [--measure expected|fitted]
//                         [--criterion least-known|d-optimal] [--max-pushes 60]
//                         [--threads 2] [--csv FILE] [--verbose]
//                         [--no-correlations]
//
// expected: the trajectory fit's Fisher information at the truth, for both arms;
// fitted: every push simulated with noise and all the pushes so far fitted together.
// A plain program: prints one line per slider, then the medians, their ratio and the
// distribution of the per-slider ratios. Exit 0; 2 for a bad option.

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "benchmarks/bench_args.h"
#include "estimator/parallel_for.h"
#include "fixtures/push_race.h"

namespace slideid {
namespace {

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n == 0 ? 0 : n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double Quantile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  if (v.empty()) return 0;
  const double pos = q * (v.size() - 1);
  const size_t lo = static_cast<size_t>(pos);
  const size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (pos - lo) * (v[hi] - v[lo]);
}

int Main(int argc, char** argv) {
  int sliders = 50, threads = 2;
  std::uint64_t seed = 1;
  RaceMeasure measure = RaceMeasure::kExpected;
  RaceOptions options;
  std::string csv;
  bool verbose = false;  // every push's relative standard errors, per slider and arm
  try {
    bench::Args args(argc, argv);
    while (args.Next()) {
      if (args.Is("--sliders")) {
        sliders = args.Integer(1);
      } else if (args.Is("--seed")) {
        seed = static_cast<std::uint64_t>(args.Integer(0));
      } else if (args.Is("--threads")) {
        threads = args.Integer(1);
      } else if (args.Is("--max-pushes")) {
        options.max_pushes = args.Integer(1);
      } else if (args.Is("--measure")) {
        const std::string m = args.Value();
        if (m != "expected" && m != "fitted") {
          throw std::invalid_argument("--measure must be expected or fitted");
        }
        measure = m == "expected" ? RaceMeasure::kExpected : RaceMeasure::kFitted;
      } else if (args.Is("--criterion")) {
        const std::string c = args.Value();
        if (!ParseAdviceCriterion(c, &options.advice.criterion)) {
          throw std::invalid_argument("--criterion must be least-known or d-optimal");
        }
      } else if (args.Is("--no-correlations")) {
        options.correlations = false;
      } else if (args.Is("--verbose")) {
        verbose = true;
      } else if (args.Is("--csv")) {
        csv = args.Value();
      } else {
        throw std::invalid_argument("unknown option " + args.option());
      }
    }
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "advise_push_benchmark: usage: %s\n", e.what());
    return 2;
  }
  struct Row {
    RaceSlider slider;
    RaceOutcome advice, random;
  };
  std::vector<Row> rows(sliders);
  ParallelFor(sliders, threads, [&](int i) {
    rows[i].slider = DrawRaceSlider(seed, i);
    rows[i].advice = RunRace(rows[i].slider, RaceArm::kAdvice, measure, options);
    rows[i].random = RunRace(rows[i].slider, RaceArm::kRandom, measure, options);
  });
  std::printf(
      "advise_push_benchmark: %d sliders (seed %llu), measure %s, criterion %s, target "
      "%.3g%% relative standard error on each of a, b, c, at most %d pushes\n",
      sliders, static_cast<unsigned long long>(seed), ToString(measure),
      ToString(options.advice.criterion), 100 * options.target_relative_stderr, options.max_pushes);
  std::printf("%5s  %-16s  %6s  %6s  %7s  %6s  %7s  %7s  %7s\n", "slider", "kind", "a", "b",
              "c [mm]", "advice", "random", "ratio", "redraws");
  std::vector<double> advice, random, ratios;
  std::ofstream out;
  if (!csv.empty()) {
    out.open(csv);
    out << "slider,kind,a,b,c_m,mu_pusher,advice_pushes,advice_reached,random_pushes,"
           "random_reached,ratio\n";
  }
  int advice_reached = 0, random_reached = 0;
  for (int i = 0; i < sliders; ++i) {
    const Row& r = rows[i];
    const double ratio = static_cast<double>(r.advice.pushes) / r.random.pushes;
    advice.push_back(r.advice.pushes);
    random.push_back(r.random.pushes);
    ratios.push_back(ratio);
    advice_reached += r.advice.reached;
    random_reached += r.random.reached;
    const auto count = [&](const RaceOutcome& o) {
      return o.reached ? std::to_string(o.pushes) : ">" + std::to_string(options.max_pushes);
    };
    std::printf("%5d  %-16s  %6.3f  %6.3f  %7.2f  %6s  %7s  %7.3f  %7d\n", i, r.slider.kind.c_str(),
                r.slider.truth.a, r.slider.truth.b, r.slider.truth.c * 1e3, count(r.advice).c_str(),
                count(r.random).c_str(), ratio, r.random.failed_pushes);
    if (verbose) {
      for (const RaceOutcome* o : {&r.advice, &r.random}) {
        std::printf("       %s:", o == &r.advice ? "advice" : "random");
        for (const auto& se : o->relative_stderr) {
          std::printf(" %.2g/%.2g/%.2g", 100 * se[0], 100 * se[1], 100 * se[2]);
        }
        std::printf(" (%%)\n");
      }
    }
    if (out) {
      out << i << "," << r.slider.kind << "," << r.slider.truth.a << "," << r.slider.truth.b << ","
          << r.slider.truth.c << "," << r.slider.mu_pusher << "," << r.advice.pushes << ","
          << r.advice.reached << "," << r.random.pushes << "," << r.random.reached << "," << ratio
          << "\n";
    }
  }
  const double ma = Median(advice), mr = Median(random);
  std::printf("pushes needed, median: advice %.1f, random %.1f; ratio of the medians %.3f\n", ma,
              mr, ma / mr);
  std::printf(
      "per-slider ratio advice / random: median %.3f, quartiles %.3f %.3f, range %.3f "
      "to %.3f; advice needed at most half on %d of %d sliders\n",
      Median(ratios), Quantile(ratios, 0.25), Quantile(ratios, 0.75),
      *std::min_element(ratios.begin(), ratios.end()),
      *std::max_element(ratios.begin(), ratios.end()),
      static_cast<int>(
          std::count_if(ratios.begin(), ratios.end(), [](double x) { return x <= 0.5; })),
      sliders);
  std::printf(
      "reached the target within %d pushes: advice %d, random %d of %d (a slider that "
      "did not counts as %d)\n",
      options.max_pushes, advice_reached, random_reached, sliders, options.max_pushes + 1);
  return 0;
}

}  // namespace
}  // namespace slideid

int main(int argc, char** argv) { return slideid::Main(argc, argv); }

#pragma once
// Order statistics the estimators, importers and predictions share: the median, quantiles
// and the MAD scale.

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace slideid {

/// 1.4826 MAD estimates the standard deviation of Gaussian data.
constexpr double kMadToSigma = 1.4826;

/// Median of chi-square with 3 degrees of freedom over its mean: a residual row's squared
/// norm (three channels) has median 0.789 times its mean under Gaussian noise.
constexpr double kChi3MedianOverMean = 2.365974 / 3.0;

/// Median of `x` (mean of the two middle values for an even count); `x` must not be empty.
inline double Median(std::vector<double> x) {
  const size_t n = x.size();
  std::nth_element(x.begin(), x.begin() + n / 2, x.end());
  const double upper = x[n / 2];
  if (n % 2 == 1) return upper;
  const double lower = *std::max_element(x.begin(), x.begin() + n / 2);
  return 0.5 * (lower + upper);
}

/// The q-quantile of `x` (0 <= q <= 1), linear between order statistics: the value at
/// position q (n - 1) of the sorted values; `x` must not be empty.
inline double Quantile(std::vector<double> x, double q) {
  std::sort(x.begin(), x.end());
  const double at = q * static_cast<double>(x.size() - 1);
  const size_t i = static_cast<size_t>(at);
  if (i + 1 >= x.size()) return x.back();
  return x[i] + (at - static_cast<double>(i)) * (x[i + 1] - x[i]);
}

/// The RMS norm of residual rows of three channels, robustly: from the median of their
/// squared norms (kChi3MedianOverMean), so that outlying rows do not set it; `squared_norms`
/// must not be empty.
inline double RobustRowRms(std::vector<double> squared_norms) {
  return std::sqrt(Median(std::move(squared_norms)) / kChi3MedianOverMean);
}

}  // namespace slideid

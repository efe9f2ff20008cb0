#pragma once
// Order statistics the estimators share: the median and the MAD scale.

#include <algorithm>
#include <vector>

namespace slideid {

/// 1.4826 MAD estimates the standard deviation of Gaussian data.
constexpr double kMadToSigma = 1.4826;

/// Median of `x` (mean of the two middle values for an even count); `x` must not be empty.
inline double Median(std::vector<double> x) {
  const size_t n = x.size();
  std::nth_element(x.begin(), x.begin() + n / 2, x.end());
  const double upper = x[n / 2];
  if (n % 2 == 1) return upper;
  const double lower = *std::max_element(x.begin(), x.begin() + n / 2);
  return 0.5 * (lower + upper);
}

}  // namespace slideid

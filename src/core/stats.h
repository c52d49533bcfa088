// Order statistics of plain samples, shared by the stages (scene: ground and roof heights; recovery: where
// a wall's outline points lie; city: the ring's ground height).
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace hsr {

/// q-quantile (0 <= q <= 1) of `values` by nearest rank: the element of rank min(n - 1, floor(q n)) in
/// ascending order; 0 for no values. Takes the values by copy (they are reordered).
inline double quantile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  const std::size_t k = std::min(values.size() - 1, static_cast<std::size_t>(q * static_cast<double>(values.size())));
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}

/// Median of `values` (non-empty): the middle element, or the mean of the two middle ones for an even count.
inline double median(std::vector<double> values) {
  const std::size_t m = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(m), values.end());
  const double upper = values[m];
  if (values.size() % 2) return upper;
  return 0.5 * (*std::max_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(m)) + upper);
}

}  // namespace hsr

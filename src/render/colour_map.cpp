// Colour maps: ColorBrewer RdBu (diverging, white at 0) and the Okabe-Ito palette for classes.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "focal/curvature/curvature.h"
#include "focal/render/render.h"

namespace focal {
namespace {

// ColorBrewer RdBu, 9 classes, from blue (low) to red (high); the middle entry is near white.
constexpr std::array<Rgb, 9> kRdBu{{{33, 102, 172},
                                    {67, 147, 195},
                                    {146, 197, 222},
                                    {209, 229, 240},
                                    {247, 247, 247},
                                    {253, 219, 199},
                                    {244, 165, 130},
                                    {214, 96, 77},
                                    {178, 24, 43}}};

// Okabe & Ito (2008), distinguishable with the common colour-vision deficiencies; indexed by
// PointClass: elliptic, hyperbolic, parabolic, umbilic, flat (undefined is grey).
constexpr std::array<Rgb, 5> kClassColours{
    {{213, 94, 0}, {0, 114, 178}, {0, 158, 115}, {204, 121, 167}, {240, 228, 66}}};

/// The RdBu map at t in [0, 1], linear between its entries.
Rgb diverging_at(double t) {
  const double x = std::clamp(t, 0.0, 1.0) * static_cast<double>(kRdBu.size() - 1);
  const auto i = std::min(static_cast<std::size_t>(x), kRdBu.size() - 2);
  const double w = x - static_cast<double>(i);
  Rgb out{};
  for (int c = 0; c < 3; ++c) {
    out[c] = static_cast<std::uint8_t>(std::lround((1.0 - w) * kRdBu[i][c] + w * kRdBu[i + 1][c]));
  }
  return out;
}

/// Where `value` lies on the map, in [0, 1] (see ColourRange).
double map_position(double value, const ColourRange& r) {
  if (r.lo < 0.0 && r.hi > 0.0) {
    return value >= 0.0 ? 0.5 + 0.5 * std::min(value / r.hi, 1.0)
                        : 0.5 - 0.5 * std::min(value / r.lo, 1.0);
  }
  if (!(r.hi > r.lo)) return 0.5;
  return (value - r.lo) / (r.hi - r.lo);
}

}  // namespace

Rgb grey_for_missing() { return {128, 128, 128}; }

Rgb map_colour(ColourMap map, double value, const ColourRange& range) {
  if (std::isnan(value)) return grey_for_missing();
  if (map == ColourMap::classes) {
    const bool known = value >= 0.0 && value < static_cast<double>(kClassColours.size()) &&
                       value == std::floor(value);
    return known ? kClassColours[static_cast<std::size_t>(value)] : grey_for_missing();
  }
  return diverging_at(map_position(value, range));
}

ColourRange robust_symmetric_range(const Eigen::Ref<const Eigen::VectorXd>& values,
                                   double percentile) {
  if (!(percentile > 0.0 && percentile <= 100.0)) {
    throw InvalidInput("robust_symmetric_range: percentile must be in (0, 100], got " +
                       std::to_string(percentile));
  }
  std::vector<double> magnitudes;
  magnitudes.reserve(static_cast<std::size_t>(values.size()));
  for (double v : values) {
    if (std::isfinite(v)) magnitudes.push_back(std::abs(v));
  }
  if (magnitudes.empty()) return {-1.0, 1.0};
  // Nearest-rank percentile.
  const auto rank = static_cast<std::size_t>(
      std::ceil(percentile / 100.0 * static_cast<double>(magnitudes.size())));
  const std::size_t k = std::clamp<std::size_t>(rank, 1, magnitudes.size()) - 1;
  std::nth_element(magnitudes.begin(), magnitudes.begin() + static_cast<std::ptrdiff_t>(k),
                   magnitudes.end());
  const double p = magnitudes[k];
  return p > 0.0 ? ColourRange{-p, p} : ColourRange{-1.0, 1.0};
}

}  // namespace focal

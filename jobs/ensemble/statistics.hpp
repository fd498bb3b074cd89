#pragma once
// The aggregate's statistics over an ensemble's members, cell by cell: the probability that a
// member's maximum reaches a threshold and the members' percentiles. Pure functions of the members'
// values (no files), so that the exact cases (identical members: 0 or 1; two members: 0.5) are
// checked on their own.
#include <cstddef>
#include <cstdint>
#include <vector>

namespace runout::jobs::ensemble {

/// One quantity (e.g. max depth) of every member on one grid: member m's cell c is v[m * cells + c].
/// Values are stored as the rasters hold them (Float32), so reading a member back changes nothing.
struct MemberStack {
  std::size_t cells = 0;
  int members = 0;
  std::vector<float> v;
  float at(int m, std::size_t c) const { return v[std::size_t(m) * cells + c]; }
};

/// Per cell, the fraction of members whose value exceeds `threshold` (`strict`: value > threshold,
/// else value >= threshold; both in Float32, as the rasters hold them: a member whose raster shows
/// exactly the threshold does not exceed it); the count divided by the members, so one of two is exactly 0.5.
/// Cells where `outside` is 1 are NaN.
std::vector<double> exceedance_probability(const MemberStack& s, double threshold, bool strict, const std::vector<std::uint8_t>& outside);

/// Per cell, the members' percentiles `p` (0-100, ascending) by linear interpolation between the
/// order statistics (numpy's default, Hyndman and Fan's type 7): out[k][c]. Cells where `outside`
/// is 1 are NaN.
std::vector<std::vector<double>> percentiles(const MemberStack& s, const std::vector<double>& p, const std::vector<std::uint8_t>& outside);

/// The percentile p (0-100) of values (type 7, as above); NaN for none. `values` is sorted in place.
double percentile_of(std::vector<double>& values, double p);

}  // namespace runout::jobs::ensemble

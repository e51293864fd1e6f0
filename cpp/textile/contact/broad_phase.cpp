#include "broad_phase.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>

namespace textile::contact
{

namespace
{
using Box = std::array<double, 6>;       // lo x, y, z, hi x, y, z
using CellRange = std::array<std::int64_t, 6>;

// 21 bits per axis pack a cell into one 64-bit key.
constexpr std::int64_t max_cells_per_axis = (std::int64_t{1} << 21) - 1;

std::uint64_t pack(std::int64_t i, std::int64_t j, std::int64_t k)
{
  return (static_cast<std::uint64_t>(i) << 42) | (static_cast<std::uint64_t>(j) << 21)
         | static_cast<std::uint64_t>(k);
}

bool overlap(const Box& a, const Box& b)
{
  for (int d = 0; d < 3; ++d)
    if (a[d] > b[d + 3] || b[d] > a[d + 3])
      return false;
  return true;
}
} // namespace

bool self_excluded(const Segment& a, const Segment& b, double self_exclusion)
{
  if (a.fibre != b.fibre)
    return false;
  const double gap = a.index < b.index ? b.arc0 - a.arc1 : a.arc0 - b.arc1;
  // a segment with itself, or a zero-length separation, is never a contact
  return a.index == b.index || gap < self_exclusion;
}

std::vector<std::pair<int, int>> find_candidate_pairs(std::span<const Segment> segments,
                                                      std::span<const double> reach,
                                                      double self_exclusion)
{
  const std::size_t n = segments.size();
  if (reach.size() != n)
    throw std::invalid_argument("find_candidate_pairs: reach has " + std::to_string(reach.size())
                                + " entries for " + std::to_string(n) + " segments");
  if (std::isnan(self_exclusion) || self_exclusion < 0.0)
    throw std::invalid_argument("find_candidate_pairs: self_exclusion must be >= 0, got "
                                + std::to_string(self_exclusion));
  if (n > static_cast<std::size_t>(std::numeric_limits<int>::max()))
    throw std::invalid_argument("find_candidate_pairs: too many segments for int numbering");
  if (n < 2)
    return {};

  std::vector<Box> box(n);
  std::vector<double> extent(n);
  std::array<double, 3> origin;
  origin.fill(std::numeric_limits<double>::infinity());
  std::array<double, 3> top;
  top.fill(-std::numeric_limits<double>::infinity());
  for (std::size_t s = 0; s < n; ++s)
  {
    if (!(std::isfinite(reach[s]) && reach[s] >= 0.0))
      throw std::invalid_argument("find_candidate_pairs: reach of segment " + std::to_string(s)
                                  + " must be finite and >= 0, got " + std::to_string(reach[s]));
    const Segment& g = segments[s];
    double e = 0.0;
    for (int d = 0; d < 3; ++d)
    {
      box[s][d] = std::min(g.p0[d], g.p1[d]) - reach[s];
      box[s][d + 3] = std::max(g.p0[d], g.p1[d]) + reach[s];
      if (!(std::isfinite(box[s][d]) && std::isfinite(box[s][d + 3])))
        throw std::invalid_argument("find_candidate_pairs: segment " + std::to_string(s)
                                    + " has a NaN or infinite coordinate");
      e = std::max(e, box[s][d + 3] - box[s][d]);
      origin[d] = std::min(origin[d], box[s][d]);
      top[d] = std::max(top[d], box[s][d + 3]);
    }
    extent[s] = e;
  }

  // Cell size: the median box extent keeps a typical box within 2^3 cells.
  std::vector<double> sorted_extent = extent;
  std::nth_element(sorted_extent.begin(), sorted_extent.begin() + n / 2, sorted_extent.end());
  double h = sorted_extent[n / 2];
  double span = 0.0;
  for (int d = 0; d < 3; ++d)
    span = std::max(span, top[d] - origin[d]);
  if (!(h > 0.0))
    h = span > 0.0 ? span : 1.0;
  h = std::max(h, span / static_cast<double>(max_cells_per_axis - 1));

  std::vector<CellRange> cells(n);
  auto bin = [&](double cell_size) -> double
  {
    double total = 0; // double: a pathological box could overflow an integer count
    for (std::size_t s = 0; s < n; ++s)
    {
      double count = 1;
      for (int d = 0; d < 3; ++d)
      {
        cells[s][d] = static_cast<std::int64_t>(std::floor((box[s][d] - origin[d]) / cell_size));
        cells[s][d + 3]
            = static_cast<std::int64_t>(std::floor((box[s][d + 3] - origin[d]) / cell_size));
        count *= static_cast<double>(cells[s][d + 3] - cells[s][d] + 1);
      }
      total += count;
    }
    return total;
  };
  // A few outsized boxes (long elements) must not blow up the grid's memory.
  while (bin(h) > 16.0 * static_cast<double>(n) + 1024.0)
    h *= 2.0;

  std::vector<std::pair<std::uint64_t, int>> entries;
  for (std::size_t s = 0; s < n; ++s)
    for (std::int64_t i = cells[s][0]; i <= cells[s][3]; ++i)
      for (std::int64_t j = cells[s][1]; j <= cells[s][4]; ++j)
        for (std::int64_t k = cells[s][2]; k <= cells[s][5]; ++k)
          entries.emplace_back(pack(i, j, k), static_cast<int>(s));
  std::sort(entries.begin(), entries.end());

  std::vector<std::pair<int, int>> pairs;
  for (std::size_t begin = 0; begin < entries.size();)
  {
    std::size_t end = begin + 1;
    while (end < entries.size() && entries[end].first == entries[begin].first)
      ++end;
    const std::uint64_t key = entries[begin].first;
    for (std::size_t p = begin; p < end; ++p)
    {
      const int a = entries[p].second;
      for (std::size_t q = p + 1; q < end; ++q)
      {
        const int b = entries[q].second; // b > a: entries are sorted by segment within a cell
        if (!overlap(box[a], box[b]))
          continue;
        // Report a pair only in the cell holding the low corner of the two
        // boxes' intersection, so a pair sharing several cells appears once.
        const std::uint64_t low = pack(std::max(cells[a][0], cells[b][0]),
                                       std::max(cells[a][1], cells[b][1]),
                                       std::max(cells[a][2], cells[b][2]));
        if (low != key || self_excluded(segments[a], segments[b], self_exclusion))
          continue;
        pairs.emplace_back(a, b);
      }
    }
    begin = end;
  }
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

} // namespace textile::contact

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

  // Dense cell ids through an open-addressing hash table, then a stable
  // counting sort of (cell, segment) entries: linear, and each cell lists
  // its segments in increasing order.
  std::size_t num_entries = 0;
  for (std::size_t s = 0; s < n; ++s)
    num_entries += static_cast<std::size_t>((cells[s][3] - cells[s][0] + 1)
                                            * (cells[s][4] - cells[s][1] + 1)
                                            * (cells[s][5] - cells[s][2] + 1));
  constexpr std::uint64_t empty = std::numeric_limits<std::uint64_t>::max();
  int bits = 4;
  while ((std::size_t{1} << bits) < 2 * n)
    ++bits;
  std::vector<std::uint64_t> slot_key(std::size_t{1} << bits, empty);
  std::vector<int> slot_cell(slot_key.size());
  std::vector<std::uint64_t> cell_key;
  std::vector<int> entry_cell;
  entry_cell.reserve(num_entries);
  // Fibonacci hashing: the high bits of the product mix all three indices.
  auto home = [&](std::uint64_t key) { return (key * 0x9E3779B97F4A7C15ull) >> (64 - bits); };
  auto cell_id = [&](std::uint64_t key)
  {
    const std::size_t mask = slot_key.size() - 1;
    std::size_t slot = home(key);
    while (slot_key[slot] != empty && slot_key[slot] != key)
      slot = (slot + 1) & mask;
    if (slot_key[slot] == key)
      return slot_cell[slot];
    if (2 * (cell_key.size() + 1) > slot_key.size()) // keep the load below 1/2
    {
      ++bits;
      slot_key.assign(std::size_t{1} << bits, empty);
      slot_cell.resize(slot_key.size());
      for (std::size_t c = 0; c < cell_key.size(); ++c)
      {
        std::size_t t = home(cell_key[c]);
        while (slot_key[t] != empty)
          t = (t + 1) & (slot_key.size() - 1);
        slot_key[t] = cell_key[c];
        slot_cell[t] = static_cast<int>(c);
      }
      slot = home(key);
      while (slot_key[slot] != empty)
        slot = (slot + 1) & (slot_key.size() - 1);
    }
    slot_key[slot] = key;
    slot_cell[slot] = static_cast<int>(cell_key.size());
    cell_key.push_back(key);
    return slot_cell[slot];
  };
  for (std::size_t s = 0; s < n; ++s)
    for (std::int64_t i = cells[s][0]; i <= cells[s][3]; ++i)
      for (std::int64_t j = cells[s][1]; j <= cells[s][4]; ++j)
        for (std::int64_t k = cells[s][2]; k <= cells[s][5]; ++k)
          entry_cell.push_back(cell_id(pack(i, j, k)));
  const std::size_t num_cells = cell_key.size();
  std::vector<std::size_t> cell_start(num_cells + 1, 0);
  for (const int c : entry_cell)
    ++cell_start[c + 1];
  for (std::size_t c = 0; c < num_cells; ++c)
    cell_start[c + 1] += cell_start[c];
  std::vector<int> cell_segments(num_entries);
  {
    std::vector<std::size_t> fill(cell_start.begin(), cell_start.end() - 1);
    std::size_t e = 0;
    for (std::size_t s = 0; s < n; ++s)
    {
      const std::size_t count = static_cast<std::size_t>((cells[s][3] - cells[s][0] + 1)
                                                         * (cells[s][4] - cells[s][1] + 1)
                                                         * (cells[s][5] - cells[s][2] + 1));
      for (std::size_t m = 0; m < count; ++m, ++e)
        cell_segments[fill[entry_cell[e]]++] = static_cast<int>(s);
    }
  }

  std::vector<std::pair<int, int>> found;
  for (std::size_t c = 0; c < num_cells; ++c)
  {
    const std::uint64_t key = cell_key[c];
    for (std::size_t p = cell_start[c]; p < cell_start[c + 1]; ++p)
    {
      const int a = cell_segments[p];
      for (std::size_t q = p + 1; q < cell_start[c + 1]; ++q)
      {
        const int b = cell_segments[q]; // b > a: the counting sort is stable
        if (!overlap(box[a], box[b]))
          continue;
        // Report a pair only in the cell holding the low corner of the two
        // boxes' intersection, so a pair sharing several cells appears once.
        const std::uint64_t low = pack(std::max(cells[a][0], cells[b][0]),
                                       std::max(cells[a][1], cells[b][1]),
                                       std::max(cells[a][2], cells[b][2]));
        if (low != key || self_excluded(segments[a], segments[b], self_exclusion))
          continue;
        found.emplace_back(a, b);
      }
    }
  }

  // Deterministic order (i, j) in linear time: bucket by i, then sort each
  // bucket's few j.
  std::vector<std::size_t> first(n + 1, 0);
  for (const auto& [a, b] : found)
    ++first[a + 1];
  for (std::size_t s = 0; s < n; ++s)
    first[s + 1] += first[s];
  std::vector<std::pair<int, int>> pairs(found.size());
  {
    std::vector<std::size_t> fill(first.begin(), first.end() - 1);
    for (const auto& pr : found)
      pairs[fill[pr.first]++] = pr;
  }
  for (std::size_t s = 0; s < n; ++s)
    std::sort(pairs.begin() + first[s], pairs.begin() + first[s + 1]);
  return pairs;
}

} // namespace textile::contact

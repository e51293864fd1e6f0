#include "history_handover.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace textile::contact
{

std::vector<std::vector<ContactElementState>>
history_handover(const ContactSet& set, const NodeOwners& owners,
                 std::span<const std::int64_t> first_node, int order, int num_ranks,
                 double max_distance)
{
  if (order < 1 or num_ranks < 1 or first_node.size() < 2)
    throw std::invalid_argument("history_handover: bad order, rank count or first_node");
  std::vector<std::vector<ContactElementState>> out(num_ranks);
  std::vector<int> to;
  for (const ContactElementState& e : set.elements())
  {
    const bool on_i = (e.fibre_i + e.fibre_j) % 2 == 0; // the fibre evaluated_here picks
    const int f = on_i ? e.fibre_i : e.fibre_j;
    const double s = on_i ? e.s_i : e.s_j;
    if (f < 0 or f + 1 >= static_cast<int>(first_node.size()))
      throw std::invalid_argument("history_handover: fibre out of range");
    const std::int64_t elements = (first_node[f + 1] - first_node[f] - 1) / order;
    const auto lo = std::clamp<std::int64_t>(
        static_cast<std::int64_t>(std::floor(s - max_distance)), 0, elements - 1);
    const auto hi = std::clamp<std::int64_t>(
        static_cast<std::int64_t>(std::floor(s + max_distance)), 0, elements - 1);
    to.clear();
    for (std::int64_t k = lo; k <= hi; ++k)
    {
      const int r = owners.owner[first_node[f] + order * k];
      if (r != owners.rank and std::find(to.begin(), to.end(), r) == to.end())
        to.push_back(r);
    }
    for (int r : to)
    {
      if (r < 0 or r >= num_ranks)
        throw std::invalid_argument("history_handover: node owner out of range");
      out[r].push_back(e);
    }
  }
  return out;
}

ContactSet with_history(const ContactSet& set, std::span<const ContactElementState> received)
{
  std::vector<ContactElementState> all(set.elements());
  all.insert(all.end(), received.begin(), received.end());
  return ContactSet(std::move(all), set.num_zones());
}

} // namespace textile::contact

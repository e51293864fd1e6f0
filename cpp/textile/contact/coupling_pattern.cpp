#include "coupling_pattern.h"
#include "node_block_matrix.h"

#include <algorithm>

namespace textile::contact
{
std::vector<CouplingPattern::Coupling> CouplingPattern::near(const ContactSet& set, double margin)
{
  std::vector<Coupling> out;
  for (const auto& e : set.elements())
    if (e.result.gap <= margin)
      out.push_back({e.nodes_i[0], e.nodes_j[0], e.particle_i.patch_nodes(), e.particle_j.patch_nodes()});
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

bool CouplingPattern::covers(const ContactSet& set, double margin) const
{
  const auto wanted = near(set, margin);
  return std::includes(_couplings.begin(), _couplings.end(), wanted.begin(), wanted.end());
}

void CouplingPattern::add(const ContactSet& set, double margin)
{
  const auto wanted = near(set, margin);
  std::vector<Coupling> merged;
  merged.reserve(_couplings.size() + wanted.size());
  std::set_union(_couplings.begin(), _couplings.end(), wanted.begin(), wanted.end(),
                 std::back_inserter(merged));
  _couplings = std::move(merged);
}

void CouplingPattern::insert(assembly::SparsityPattern& pattern, std::span<const std::int32_t> dofs) const
{
  std::vector<std::size_t> offsets = {0};
  std::vector<std::int64_t> nodes;
  for (const auto& c : _couplings)
  {
    for (int a = 0; a < c.nodes_i; ++a)
      nodes.push_back(c.first_i + a);
    for (int a = 0; a < c.nodes_j; ++a)
      nodes.push_back(c.first_j + a);
    offsets.push_back(nodes.size());
  }
  NodeBlockMatrix blocks;
  blocks.build(offsets, nodes, dofs);
  blocks.insert_pattern(pattern);
}
} // namespace textile::contact

// Which pairs of fibre elements a system matrix has room for (contact
// couplings), so that it is rebuilt only when contact couples new ones.
//
// A contact element near closing couples every unknown of its element on
// fibre i with every unknown of its element on fibre j. The system matrix
// is preallocated (assembly/sparsity_pattern.h) for the
// couplings recorded here; when a detection pass brings an element near
// contact (its gap below a margin) on a pair of fibre elements not
// recorded, the matrix must be rebuilt. Couplings are kept once recorded
// until the contact effect starts a fresh record at a converged state
// (FibreContact.commit): a contact that opens and closes again within a
// step, or flickers between two neighbouring element pairs, does not
// rebuild the matrix each time.
#pragma once

#include "contact_set.h"
#include "../assembly/sparsity_pattern.h"

#include <petscmat.h>

#include <cstdint>
#include <span>
#include <vector>

namespace textile::contact
{

class CouplingPattern
{
public:
  /// Whether every element of `set` whose last evaluated gap is at most
  /// `margin` (length) couples a recorded pair of fibre elements.
  bool covers(const ContactSet& set, double margin) const;

  /// Record the couplings of those elements too.
  void add(const ContactSet& set, double margin);

  /// Declare the recorded couplings (9 x 9 blocks of their nodes, global
  /// indices dofs[9 node + k], -1 skipped) in a pattern being built.
  void insert(assembly::SparsityPattern& pattern, std::span<const std::int32_t> dofs) const;

  /// Number of recorded pairs of fibre elements.
  std::size_t size() const { return _couplings.size(); }

private:
  /// A pair of fibre elements: first global node and node count of each
  /// (an element's nodes are consecutive).
  struct Coupling
  {
    std::int64_t first_i = 0, first_j = 0;
    int nodes_i = 0, nodes_j = 0;
    auto operator<=>(const Coupling&) const = default;
  };
  std::vector<Coupling> _couplings; // sorted, unique

  static std::vector<Coupling> near(const ContactSet& set, double margin);
};

} // namespace textile::contact

// Contact history across ranks: the old elements whose successor another
// rank may evaluate.
//
// A rank evaluates the contact elements whose first node (on the fibre
// that evaluated_here picks) it owns (contact_set.h). When the fibres
// slide, the element of the next detection pass that takes over an old
// element's history (match_history, history_transfer.h) may start at a node
// of another rank: without its predecessor there, it would lose its stick
// point, normal orientation and penalty (a capstan split between ranks by
// place ended 3e-4 off its one-rank tension ratio). The successor is within
// history_match_distance of the old element on both fibres, so only the
// elements next to a partition cut are handed over, to the ranks owning the
// first nodes of the elements within that distance.
#pragma once

#include "contact_set.h"

#include <cstdint>
#include <span>
#include <vector>

namespace textile::contact
{

/// For each rank r (0 .. num_ranks - 1), the elements of `set` whose
/// successor rank r may evaluate and this rank does not own: the elements
/// whose abscissa on the fibre evaluated_here picks is within
/// `max_distance` of an element whose first node rank r owns. Empty for
/// this rank itself. `first_node`: per fibre, its first global node (and
/// the total at the end); `order`: nodes per element minus one.
std::vector<std::vector<ContactElementState>>
history_handover(const ContactSet& set, const NodeOwners& owners,
                 std::span<const std::int64_t> first_node, int order, int num_ranks,
                 double max_distance);

/// A set holding `set`'s elements followed by `received` (another rank's
/// history): to find predecessors in, never to assemble.
ContactSet with_history(const ContactSet& set, std::span<const ContactElementState> received);

} // namespace textile::contact

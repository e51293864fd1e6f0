#include "contact_set.h"
#include "../node_unknowns.h"
#include "../assembly/petsc_error.h"
#include "regularized_penalty.h"
#include "../geometry_error.h"

#include <algorithm>
#include <chrono>
#include <optional>
#include <stdexcept>

namespace textile::contact
{
namespace
{
using assembly::check;
using Clock = std::chrono::steady_clock;

constexpr int max_element_dofs = max_patch_nodes * dofs_per_node; // a side's patch
constexpr int max_pair_dofs = 2 * max_element_dofs;

double seconds_since(Clock::time_point t0)
{
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

/// Current unknowns of one fibre element (9 per node) copied from q.
std::span<const double> gather(const std::array<std::int64_t, max_patch_nodes>& nodes, int num_nodes,
                               std::span<const double> q,
                               std::array<double, max_element_dofs>& buffer)
{
  if (num_nodes < 2 or num_nodes > max_patch_nodes)
    throw std::invalid_argument("ContactSet: a contact patch has 2 to 5 nodes");
  for (int a = 0; a < num_nodes; ++a)
    std::copy_n(q.data() + dofs_per_node * nodes[a], dofs_per_node,
                buffer.data() + dofs_per_node * a);
  return std::span<const double>(buffer.data(), dofs_per_node * num_nodes);
}

/// Unknowns of both fibre elements of a contact element, [element i, element j].
struct ElementUnknowns
{
  std::array<double, max_element_dofs> bi, bj;
  std::span<const double> xi, xj;
  ElementUnknowns(const ContactElementState& e, std::span<const double> q)
      : xi(gather(e.nodes_i, e.particle_i.patch_nodes(), q, bi)),
        xj(gather(e.nodes_j, e.particle_j.patch_nodes(), q, bj))
  {
  }
  std::size_t size() const { return xi.size() + xj.size(); }
};

/// Global indices of the element pair's unknowns, [element i, element j].
void element_dofs(const ContactElementState& e, std::span<const std::int32_t> dofs,
                  std::array<std::int32_t, max_pair_dofs>& idx)
{
  std::size_t k = 0;
  for (int a = 0; a < e.particle_i.patch_nodes(); ++a)
    for (int d = 0; d < dofs_per_node; ++d)
      idx[k++] = dofs[dofs_per_node * e.nodes_i[a] + d];
  for (int a = 0; a < e.particle_j.patch_nodes(); ++a)
    for (int d = 0; d < dofs_per_node; ++d)
      idx[k++] = dofs[dofs_per_node * e.nodes_j[a] + d];
}

/// The element's law: an element standing for `length` of contact has the
/// per-length law times its length (R_N and friction are linear in k).
RegularizedPenalty element_law(const ContactElementState& e)
{
  return RegularizedPenalty(e.penalty * e.length, e.regularization, e.tangent_floor);
}

/// Open: no force and no stiffness at this gap (for this law, gap >= 0):
/// nothing in the residual.
bool is_open(const RegularizedPenalty& law, double gap)
{
  return law.reaction(gap) == 0 and law.stiffness(gap) == 0;
}

/// Nothing in the tangent either (the tangent floor reaches open elements
/// just before contact).
bool is_open_in_tangent(const RegularizedPenalty& law, double gap)
{
  return is_open(law, gap) and law.newton_stiffness(gap) == 0;
}
} // namespace

ContactSet::ContactSet(std::vector<ContactElementState> elements, int num_zones)
    : _elements(std::move(elements)), _num_zones(num_zones)
{
  for (const auto& e : _elements)
    if (e.zone < 0 or e.zone >= num_zones)
      throw std::invalid_argument("ContactSet: element zone outside 0 .. num_zones - 1");
}

ContactSet::ContactSet(const ContactSet& other)
    : _elements(other._elements), _num_zones(other._num_zones), _depth_scale(other._depth_scale),
      _motion_depth(other._motion_depth)
{
}

ContactSet& ContactSet::operator=(const ContactSet& other)
{
  if (this != &other)
  {
    _elements = other._elements;
    _num_zones = other._num_zones;
    _depth_scale = other._depth_scale;
    _motion_depth = other._motion_depth;
    _blocks = NodeBlockMatrix();
  }
  return *this;
}

ContactResult ContactSet::element(const ContactElementState& e, std::span<const double> xi,
                                  std::span<const double> xj, std::span<double> r,
                                  std::span<double> K) const
{
  // the gap decides the tangent's terms: evaluated once more when asked
  const bool motion_tangent
      = K.empty() or _motion_depth == std::numeric_limits<double>::infinity()
        or -contact_gap(e.particle_i, e.particle_j, e.normal, xi, xj, offset(e), e.motion)
               <= _motion_depth;
  return contact_element(e.particle_i, e.particle_j, e.normal, element_law(e),
                         e.friction.mu > 0 ? &e.friction : nullptr, e.stick, xi, xj, r, K,
                         offset(e), e.motion, motion_tangent);
}

bool ContactSet::take_layout(ContactSet& previous)
{
  if (previous._blocks.num_elements() != _elements.size() or _elements.empty())
    return false;
  for (std::size_t k = 0; k < _elements.size(); ++k)
  {
    const auto &a = _elements[k], &b = previous._elements[k];
    if (a.nodes_i != b.nodes_i or a.nodes_j != b.nodes_j
        or a.particle_i.patch_nodes() != b.particle_i.patch_nodes()
        or a.particle_j.patch_nodes() != b.particle_j.patch_nodes())
      return false;
  }
  _blocks = std::move(previous._blocks);
  previous._blocks = NodeBlockMatrix();
  return true;
}

void ContactSet::evaluate(std::span<const double> q)
{
  std::array<double, max_pair_dofs> r;
  for (auto& e : _elements)
  {
    const ElementUnknowns x(e, q);
    e.result = element(e, x.xi, x.xj, std::span<double>(r.data(), x.size()), {});
  }
}

std::size_t ContactSet::run_kernels(std::span<const double> q)
{
  std::array<double, max_pair_dofs> r;
  std::size_t count = 0;
  for (const auto& e : _elements)
  {
    const ElementUnknowns x(e, q);
    if (is_open(element_law(e), contact_gap(e.particle_i, e.particle_j, e.normal, x.xi, x.xj, offset(e), e.motion)))
      continue;
    const std::size_t n = x.size();
    _K.resize(n * n);
    element(e, x.xi, x.xj, std::span<double>(r.data(), n), {});
    element(e, x.xi, x.xj, std::span<double>(r.data(), n), _K);
    count += 2;
  }
  return count;
}

std::vector<std::int64_t> ContactSet::nodes() const
{
  std::vector<std::int64_t> out;
  for (const auto& e : _elements)
  {
    for (int a = 0; a < e.particle_i.patch_nodes(); ++a)
      out.push_back(e.nodes_i[a]);
    for (int a = 0; a < e.particle_j.patch_nodes(); ++a)
      out.push_back(e.nodes_j[a]);
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

std::vector<double> ContactSet::nodal_forces(std::span<const double> q) const
{
  std::vector<double> out(q.size(), 0.0);
  std::array<double, max_pair_dofs> r;
  for (const auto& e : _elements)
  {
    const ElementUnknowns x(e, q);
    if (is_open(element_law(e), contact_gap(e.particle_i, e.particle_j, e.normal, x.xi, x.xj, offset(e), e.motion)))
      continue;
    element(e, x.xi, x.xj, std::span<double>(r.data(), x.size()), {});
    std::size_t k = 0;
    for (int a = 0; a < e.particle_i.patch_nodes(); ++a)
      for (int d = 0; d < dofs_per_node; ++d)
        out[dofs_per_node * e.nodes_i[a] + d] += r[k++];
    for (int a = 0; a < e.particle_j.patch_nodes(); ++a)
      for (int d = 0; d < dofs_per_node; ++d)
        out[dofs_per_node * e.nodes_j[a] + d] += r[k++];
  }
  return out;
}

void ContactSet::assemble_vector(std::span<const double> q, std::span<const std::int32_t> dofs,
                                 Vec b)
{
  const auto t0 = Clock::now();
  std::array<double, max_pair_dofs> r;
  std::array<std::int32_t, max_pair_dofs> idx;
  // an element outside its domain (gap_function.h) ends the assembly with
  // its error once the others are in: callers make the residual infinite
  std::optional<GeometryError> error;
  for (auto& e : _elements)
  try
  {
    const ElementUnknowns x(e, q);
    const double gap = contact_gap(e.particle_i, e.particle_j, e.normal, x.xi, x.xj, offset(e), e.motion);
    if (is_open(element_law(e), gap))
    {
      e.result = ContactResult{};
      e.result.gap = gap;
      continue;
    }
    const std::size_t n = x.size();
    const auto tk = Clock::now();
    e.result = element(e, x.xi, x.xj, std::span<double>(r.data(), n), {});
    _timing.kernel += seconds_since(tk);
    ++_timing.kernel_calls;
    element_dofs(e, dofs, idx);
    check(VecSetValues(b, static_cast<PetscInt>(n), idx.data(), r.data(), ADD_VALUES),
          "VecSetValues");
  }
  catch (const GeometryError& err)
  {
    error = error ? error : err;
  }
  _timing.total += seconds_since(t0);
  if (error)
    throw *error;
}

void ContactSet::assemble_matrix(std::span<const double> q, std::span<const std::int32_t> dofs,
                                 Mat A)
{
  const auto t0 = Clock::now();
  if (!_blocks.built_for(dofs))
  {
    // every element may close during a Newton solve: lay out all of them
    std::vector<std::size_t> offsets = {0};
    std::vector<std::int64_t> nodes;
    for (const auto& e : _elements)
    {
      nodes.insert(nodes.end(), e.nodes_i.begin(), e.nodes_i.begin() + e.particle_i.patch_nodes());
      nodes.insert(nodes.end(), e.nodes_j.begin(), e.nodes_j.begin() + e.particle_j.patch_nodes());
      offsets.push_back(nodes.size());
    }
    _blocks.build(offsets, nodes, dofs);
  }
  std::array<double, max_pair_dofs> r;
  // an element outside its domain: the others are inserted (the insertion
  // is collective), then its error is raised
  std::optional<GeometryError> error;
  for (std::size_t k = 0; k < _elements.size(); ++k)
  try
  {
    auto& e = _elements[k];
    const ElementUnknowns x(e, q);
    if (is_open_in_tangent(element_law(e), contact_gap(e.particle_i, e.particle_j, e.normal, x.xi, x.xj, offset(e), e.motion)))
      continue;
    const std::size_t n = x.size();
    _K.resize(n * n); // the kernel overwrites it
    const auto tk = Clock::now();
    element(e, x.xi, x.xj, std::span<double>(r.data(), n), _K);
    _timing.kernel += seconds_since(tk);
    ++_timing.kernel_calls;
    _blocks.add(k, _K);
  }
  catch (const GeometryError& err)
  {
    error = error ? error : err;
  }
  const auto before = _blocks.off_rank_counts();
  _blocks.insert(A);
  _timing.off_rank_sent += _blocks.off_rank_counts().sent - before.sent;
  _timing.off_rank_stashed += _blocks.off_rank_counts().stashed - before.stashed;
  _timing.total += seconds_since(t0);
  if (error)
    throw *error;
}

Eigen::Vector3d ContactSet::elastic_slip(const ContactElementState& e) const
{
  const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - e.normal * e.normal.transpose();
  return P * (e.result.delta - e.stick);
}

std::size_t ContactSet::num_friction_histories() const
{
  std::size_t n = 0;
  for (const auto& e : _elements)
    n += e.friction.mu > 0;
  return n;
}

void ContactSet::commit()
{
  for (auto& e : _elements)
  {
    // a frictionless contact has no stick memory: its stick point follows
    // it, so friction switched on later (another stage's coefficients, a
    // saved state read by a scene with friction) starts from zero elastic
    // slip instead of the whole sliding since the element was created
    if (e.friction.mu <= 0)
      e.stick = e.result.delta;
    else if (e.result.normal_force > 0)
      e.stick = updated_stick(e.normal, e.friction, e.result.delta, e.stick);
    else
      e.stick = e.result.delta; // open: sliding starts from where contact begins
  }
}

std::vector<double> ContactSet::zone_max_penetration() const
{
  std::vector<double> out(_num_zones, 0.0);
  for (const auto& e : _elements)
    out[e.zone] = std::max(out[e.zone], -e.result.gap);
  return out;
}

std::vector<double> ContactSet::zone_penalty() const
{
  std::vector<double> out(_num_zones, 0.0);
  for (const auto& e : _elements)
    out[e.zone] = std::max(out[e.zone], e.penalty);
  return out;
}

std::vector<double> ContactSet::zone_force() const
{
  std::vector<double> out(_num_zones, 0.0);
  for (const auto& e : _elements)
    out[e.zone] += e.result.normal_force;
  return out;
}

void ContactSet::set_depths(std::span<const double> depth)
{
  if (depth.size() != _elements.size())
    throw std::invalid_argument("ContactSet::set_depths: one depth per element needed");
  for (std::size_t k = 0; k < depth.size(); ++k)
  {
    if (!(depth[k] >= 0))
      throw std::invalid_argument("ContactSet::set_depths: depths must be >= 0");
    _elements[k].depth = depth[k];
  }
}

void ContactSet::set_depth_scale(double scale)
{
  if (!(scale >= 0 and scale <= 1))
    throw std::invalid_argument("ContactSet::set_depth_scale: scale must be in [0, 1]");
  _depth_scale = scale;
}

std::vector<double> ContactSet::zone_crossed() const
{
  std::vector<double> out(_num_zones, 0.0);
  for (const auto& e : _elements)
    out[e.zone] += e.result.separation < 0;
  return out;
}

void ContactSet::set_motion_depth(double depth)
{
  if (!(depth > 0))
    throw std::invalid_argument("ContactSet::set_motion_depth: depth must be positive");
  _motion_depth = depth;
}

void ContactSet::set_tangent_floor(double fraction)
{
  if (!(fraction >= 0 and fraction <= 1))
    throw std::invalid_argument("ContactSet::set_tangent_floor: fraction must be in [0, 1]");
  for (auto& e : _elements)
    e.tangent_floor = fraction;
}

void ContactSet::set_zone_penalties(std::span<const double> k)
{
  if (k.size() != static_cast<std::size_t>(_num_zones))
    throw std::invalid_argument("ContactSet::set_zone_penalties: one penalty per zone needed");
  for (auto& e : _elements)
  {
    if (!(k[e.zone] > 0))
      throw std::invalid_argument("ContactSet::set_zone_penalties: penalties must be positive");
    e.penalty = k[e.zone];
  }
}
} // namespace textile::contact

#include "beam_assembler.h"
#include "../node_unknowns.h"
#include "../geometry_error.h"
#include "ordered_pipeline.h"
#include "petsc_insert.h"

#include <algorithm>
#include <array>
#include <stdexcept>
#include <string>

namespace textile::assembly
{
template <typename T>
void BeamAssembler::gather(std::size_t e, std::span<const T> values, std::span<T> out) const
{
  const int nn = _rule.num_nodes;
  for (int a = 0; a < nn; ++a)
  {
    const std::size_t node = _conn[e * nn + a];
    for (int k = 0; k < dofs_per_node; ++k)
      out[dofs_per_node * a + k] = values[dofs_per_node * node + k];
  }
}

void BeamAssembler::current(std::size_t e, std::span<const double> u,
                            std::span<double> xe) const
{
  const int nn = _rule.num_nodes;
  for (int a = 0; a < nn; ++a)
  {
    const std::size_t node = _conn[e * nn + a];
    for (int k = 0; k < dofs_per_node; ++k)
      xe[dofs_per_node * a + k] = _X[dofs_per_node * node + k] + u[dofs_per_node * node + k];
  }
}

BeamAssembler::BeamAssembler(beam::ElementRule rule, std::vector<std::int32_t> connectivity,
                             std::vector<std::int32_t> element_group,
                             std::vector<beam::Material> materials,
                             std::vector<beam::SectionQuadrature> sections, std::vector<double> X,
                             std::vector<std::int32_t> element_number)
    : _rule(std::move(rule)), _conn(std::move(connectivity)), _group(std::move(element_group)),
      _number(std::move(element_number)), _materials(std::move(materials)),
      _sections(std::move(sections)), _X(std::move(X))
{
  const std::size_t nn = _rule.num_nodes;
  if (nn != 2 and nn != 3)
    throw std::invalid_argument("BeamAssembler: num_nodes must be 2 or 3");
  if (_conn.size() != nn * _group.size())
    throw std::invalid_argument("BeamAssembler: connectivity size != num_elements x num_nodes");
  if (_materials.size() != _sections.size())
    throw std::invalid_argument("BeamAssembler: one section per material group expected");
  if (_X.size() % dofs_per_node != 0)
    throw std::invalid_argument("BeamAssembler: reference data must hold 9 values per node");
  const std::int32_t num_local_nodes = _X.size() / dofs_per_node;
  for (auto g : _group)
    if (g < 0 or g >= static_cast<std::int32_t>(_materials.size()))
      throw std::invalid_argument("BeamAssembler: element group out of range");
  for (auto i : _conn)
    if (i < 0 or i >= num_local_nodes)
      throw std::invalid_argument("BeamAssembler: node index out of range");
  for (auto& m : _materials)
    beam::validate(m);
  if (_number.empty())
    for (std::size_t e = 0; e < _group.size(); ++e)
      _number.push_back(static_cast<std::int32_t>(e));
  if (_number.size() != _group.size())
    throw std::invalid_argument("BeamAssembler: one element number per element expected");

  std::vector<double> Xe(dofs_per_node * nn);
  for (std::size_t e = 0; e < _group.size(); ++e)
  {
    _ref_offset.push_back(_ref.size());
    _ref.resize(_ref.size() + beam::num_points(_rule, _sections[_group[e]]));
    gather<double>(e, _X, Xe);
    try
    {
      beam::reference_points(_rule, _sections[_group[e]], Xe, {_ref.data() + _ref_offset[e],
                                                                 _ref.size() - _ref_offset[e]});
    }
    catch (const std::runtime_error& error)
    {
      throw std::runtime_error(describe(e) + ": " + error.what());
    }
  }
  _ref_offset.push_back(_ref.size());
}

std::string BeamAssembler::describe(std::size_t e) const
{
  return "element " + std::to_string(_number[e]) + " of fibre " + std::to_string(_group[e]);
}

template <typename Kernel>
auto BeamAssembler::on_element(std::size_t e, Kernel&& kernel) const
{
  try
  {
    return kernel();
  }
  catch (const GeometryError& error)
  {
    throw GeometryError(describe(e) + ": " + error.what());
  }
}

std::span<const beam::ReferencePoint> BeamAssembler::reference(std::size_t e) const
{
  return {_ref.data() + _ref_offset[e], _ref_offset[e + 1] - _ref_offset[e]};
}

void BeamAssembler::set_num_threads(int n)
{
  if (n < 1)
    throw std::invalid_argument("BeamAssembler: num_threads must be >= 1");
  _num_threads = n;
}

int BeamAssembler::threads_for_elements() const
{
  // a thread pays off only with enough elements (starting one costs about
  // as much as a few elements' residuals)
  constexpr std::size_t min_elements_per_thread = 256;
  return static_cast<int>(std::clamp<std::size_t>(_group.size() / min_elements_per_thread, 1,
                                                  _num_threads));
}

double BeamAssembler::assemble_vector(std::span<const double> u, std::span<double> b) const
{
  if (u.size() != _X.size() or b.size() != _X.size())
    throw std::invalid_argument("BeamAssembler::assemble_vector: wrong vector size");
  const std::size_t nn = _rule.num_nodes, nd = dofs_per_node * nn, ne = _group.size();
  // chunks of element forces computed on the threads, added to b (and the
  // energy summed) in element order by this thread: the result does not
  // depend on the number of threads
  const int nt = threads_for_elements();
  const std::size_t chunk = nt > 1 ? 16 : 1, slots = nt > 1 ? 4 * nt : 1;
  std::vector<double> re(slots * chunk * nd), energy(slots * chunk);
  double total = 0;
  ordered_pipeline(
      (ne + chunk - 1) / chunk, nt, slots,
      [&](std::size_t c, std::size_t slot)
      {
        std::array<double, 27> xe;
        for (std::size_t e = c * chunk, i = slot * chunk; e < std::min(ne, (c + 1) * chunk);
             ++e, ++i)
        {
          current(e, u, std::span(xe).first(nd));
          const std::span<double> r = std::span(re).subspan(i * nd, nd);
          std::fill(r.begin(), r.end(), 0.0);
          energy[i] = on_element(e, [&] {
            return beam::element_residual_tangent(_rule, _materials[_group[e]],
                                                  _sections[_group[e]], reference(e),
                                                  std::span(xe).first(nd), r, {});
          });
        }
      },
      [&](std::size_t c, std::size_t slot)
      {
        for (std::size_t e = c * chunk, i = slot * chunk; e < std::min(ne, (c + 1) * chunk);
             ++e, ++i)
        {
          total += energy[i];
          for (std::size_t a = 0; a < nn; ++a)
          {
            const std::size_t node = _conn[e * nn + a];
            for (int k = 0; k < dofs_per_node; ++k)
              b[dofs_per_node * node + k] += re[i * nd + dofs_per_node * a + k];
          }
        }
      });
  return total;
}

void BeamAssembler::assemble_matrix(Mat A, std::span<const double> u,
                                    std::span<const std::int32_t> dofs,
                                    std::span<const double> du,
                                    std::span<const double> du_weights) const
{
  // (a rank without nodes has k empty updates: their count is the weights')
  const std::size_t num_du = _X.empty() ? du_weights.size() : du.size() / _X.size();
  if (u.size() != _X.size() or dofs.size() != _X.size() or du.size() != num_du * _X.size()
      or num_du > beam::max_mip_updates
      or (!du_weights.empty() and du_weights.size() != num_du))
    throw std::invalid_argument("BeamAssembler::assemble_matrix: wrong array size");
  const int nn = _rule.num_nodes, nd = dofs_per_node * nn;
  std::vector<std::int32_t> idx(nd * _group.size());
  for (std::size_t e = 0; e < _group.size(); ++e)
    gather<std::int32_t>(e, dofs, std::span(idx).subspan(e * nd, nd));
  _insertion.add_blocks(
      A, idx, nd,
      [&](std::size_t e, std::span<double> Ke)
      {
        std::array<double, 27> xe;
        std::array<double, 27 * beam::max_mip_updates> dxe;
        current(e, u, std::span(xe).first(nd));
        for (std::size_t k = 0; k < num_du; ++k)
          gather<double>(e, du.subspan(k * _X.size(), _X.size()),
                         std::span(dxe).subspan(k * nd, nd));
        on_element(e, [&] {
          return beam::element_residual_tangent(
              _rule, _materials[_group[e]], _sections[_group[e]], reference(e),
              std::span(xe).first(nd), {}, Ke, std::span(dxe).first(num_du * nd), du_weights);
        });
      },
      threads_for_elements());
}

std::vector<double> BeamAssembler::fields(std::span<const double> u) const
{
  if (u.size() != _X.size())
    throw std::invalid_argument("BeamAssembler::fields: wrong vector size");
  const int nd = dofs_per_node * _rule.num_nodes;
  std::vector<double> xe(nd), out(12 * _group.size());
  for (std::size_t e = 0; e < _group.size(); ++e)
  {
    current(e, u, xe);
    const beam::ElementFields f = on_element(e, [&] {
      return beam::element_fields(_rule, _materials[_group[e]], _sections[_group[e]],
                                  reference(e), xe);
    });
    for (int v = 0; v < 6; ++v)
    {
      out[12 * e + v] = f.strain(v);
      out[12 * e + 6 + v] = f.stress(v);
    }
  }
  return out;
}

} // namespace textile::assembly

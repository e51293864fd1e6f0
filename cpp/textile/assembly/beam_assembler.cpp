#include "beam_assembler.h"
#include "../geometry_error.h"
#include "parallel_for.h"
#include "petsc_insert.h"

#include <array>
#include <numeric>
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
    for (int k = 0; k < beam::dofs_per_node; ++k)
      out[9 * a + k] = values[9 * node + k];
  }
}

void BeamAssembler::current(std::size_t e, std::span<const double> u,
                            std::span<double> xe) const
{
  const int nn = _rule.num_nodes;
  for (int a = 0; a < nn; ++a)
  {
    const std::size_t node = _conn[e * nn + a];
    for (int k = 0; k < beam::dofs_per_node; ++k)
      xe[9 * a + k] = _X[9 * node + k] + u[9 * node + k];
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
  if (_X.size() % beam::dofs_per_node != 0)
    throw std::invalid_argument("BeamAssembler: reference data must hold 9 values per node");
  const std::int32_t num_local_nodes = _X.size() / beam::dofs_per_node;
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

  std::vector<double> Xe(beam::dofs_per_node * nn);
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

double BeamAssembler::assemble_vector(std::span<const double> u, std::span<double> b) const
{
  if (u.size() != _X.size() or b.size() != _X.size())
    throw std::invalid_argument("BeamAssembler::assemble_vector: wrong vector size");
  const int nn = _rule.num_nodes, nd = 9 * nn;
  // thread 0 adds into b, the others into their own copies (neighbouring
  // elements share nodes), summed afterwards
  const int nt = std::max<int>(1, std::min<std::size_t>(_num_threads, _group.size()));
  std::vector<std::vector<double>> partial(nt - 1, std::vector<double>(b.size(), 0.0));
  std::vector<double> energy(nt, 0.0);
  parallel_for(_group.size(), nt,
               [&](std::size_t e0, std::size_t e1, int t)
               {
                 std::span<double> out = t == 0 ? b : std::span<double>(partial[t - 1]);
                 std::array<double, 27> xe, re;
                 for (std::size_t e = e0; e < e1; ++e)
                 {
                   current(e, u, std::span(xe).first(nd));
                   std::fill_n(re.begin(), nd, 0.0);
                   energy[t] += on_element(e, [&] {
                     return beam::element_residual_tangent(
                         _rule, _materials[_group[e]], _sections[_group[e]], reference(e),
                         std::span(xe).first(nd), std::span(re).first(nd), {});
                   });
                   for (int a = 0; a < nn; ++a)
                   {
                     const std::size_t node = _conn[e * nn + a];
                     for (int k = 0; k < 9; ++k)
                       out[9 * node + k] += re[9 * a + k];
                   }
                 }
               });
  for (const auto& p : partial)
    for (std::size_t i = 0; i < b.size(); ++i)
      b[i] += p[i];
  return std::accumulate(energy.begin(), energy.end(), 0.0);
}

void BeamAssembler::assemble_matrix(Mat A, std::span<const double> u,
                                    std::span<const std::int32_t> dofs,
                                    std::span<const double> du) const
{
  if (u.size() != _X.size() or dofs.size() != _X.size()
      or (!du.empty() and du.size() != _X.size()))
    throw std::invalid_argument("BeamAssembler::assemble_matrix: wrong array size");
  const int nn = _rule.num_nodes, nd = 9 * nn;
  std::vector<std::int32_t> idx(nd * _group.size());
  for (std::size_t e = 0; e < _group.size(); ++e)
    gather<std::int32_t>(e, dofs, std::span(idx).subspan(e * nd, nd));
  _insertion.add_blocks(
      A, idx, nd,
      [&](std::size_t e, std::span<double> Ke)
      {
        std::array<double, 27> xe, dxe;
        current(e, u, std::span(xe).first(nd));
        if (!du.empty())
          gather<double>(e, du, std::span(dxe).first(nd));
        on_element(e, [&] {
          return beam::element_residual_tangent(
              _rule, _materials[_group[e]], _sections[_group[e]], reference(e),
              std::span(xe).first(nd), {}, Ke,
              du.empty() ? std::span<const double>() : std::span(dxe).first(nd));
        });
      },
      _num_threads);
}

std::vector<double> BeamAssembler::fields(std::span<const double> u) const
{
  if (u.size() != _X.size())
    throw std::invalid_argument("BeamAssembler::fields: wrong vector size");
  const int nd = 9 * _rule.num_nodes;
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

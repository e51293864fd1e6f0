#include "junction_set.h"
#include "../node_unknowns.h"
#include "fibre_matrix_junction.h"

#include <algorithm>
#include <numeric>
#include <stdexcept>
#include <string>

namespace textile::junction
{
namespace
{
/// Where a fibre node's unknowns start in a nodal array.
std::size_t node_offset(std::int32_t node)
{
  return dofs_per_node * static_cast<std::size_t>(node);
}
} // namespace

JunctionSet::JunctionSet(double k, int num_fibre_nodes, std::vector<std::int32_t> element_nodes,
                         std::vector<double> xi, std::vector<double> section,
                         std::vector<double> weight, std::vector<double> X_fibre,
                         std::vector<double> X_matrix, std::vector<std::int32_t> cell_nodes,
                         std::vector<double> phi)
    : _k(k), _nf(num_fibre_nodes),
      _nm(xi.empty() ? 0 : static_cast<int>(cell_nodes.size() / xi.size())),
      _elem(std::move(element_nodes)), _xi(std::move(xi)), _c(std::move(section)),
      _w(std::move(weight)), _Xf(std::move(X_fibre)), _Xm(std::move(X_matrix)),
      _cells(std::move(cell_nodes)), _phi(std::move(phi))
{
  const std::size_t n = _xi.size();
  if (!(_k > 0))
    throw std::invalid_argument("JunctionSet: stiffness must be positive");
  if (_nf != 2 and _nf != 3)
    throw std::invalid_argument("JunctionSet: num_fibre_nodes must be 2 or 3");
  if (_elem.size() != n * _nf or _c.size() != 2 * n or _w.size() != n or _Xm.size() != 3 * n
      or _cells.size() != n * _nm or _phi.size() != _cells.size() or _Xf.size() % dofs_per_node)
    throw std::invalid_argument("JunctionSet: inconsistent array sizes");
  const std::size_t nfib = _Xf.size() / 9;
  for (std::size_t j = 0; j < n; ++j)
  {
    if (!(_w[j] > 0) or !(_xi[j] >= -1 and _xi[j] <= 1))
      throw std::invalid_argument("JunctionSet: junction " + std::to_string(j)
                                  + " has a non-positive weight or xi outside [-1, 1]");
    for (int a = 0; a < _nf; ++a)
      if (_elem[_nf * j + a] < 0 or static_cast<std::size_t>(_elem[_nf * j + a]) >= nfib)
        throw std::invalid_argument("JunctionSet: fibre node index out of range");
    for (int b = 0; b < _nm; ++b)
      if (_cells[_nm * j + b] < 0)
        throw std::invalid_argument("JunctionSet: negative matrix node index");
  }
  // group the junctions by (element nodes, cell nodes), keeping their order
  // within a group
  _order.resize(n);
  std::iota(_order.begin(), _order.end(), std::size_t(0));
  auto key_less = [&](std::size_t i, std::size_t j)
  {
    auto ei = _elem.begin() + _nf * i, ej = _elem.begin() + _nf * j;
    if (!std::equal(ei, ei + _nf, ej))
      return std::lexicographical_compare(ei, ei + _nf, ej, ej + _nf);
    auto ci = _cells.begin() + _nm * i, cj = _cells.begin() + _nm * j;
    return std::lexicographical_compare(ci, ci + _nm, cj, cj + _nm);
  };
  std::stable_sort(_order.begin(), _order.end(), key_less);
  _group.assign(1, 0);
  for (std::size_t i = 1; i <= n; ++i)
    if (i == n or key_less(_order[i - 1], _order[i]))
      _group.push_back(i);
  if (n == 0)
    _group.assign(1, 0);
}

void JunctionSet::gather(std::size_t j, std::span<const double> u_fibre,
                         std::span<const double> u_matrix, std::span<double> Xf,
                         std::span<double> uf, std::span<double> um) const
{
  for (int a = 0; a < _nf; ++a)
  {
    const std::size_t node = static_cast<std::size_t>(_elem[_nf * j + a]);
    for (int c = 0; c < dofs_per_node; ++c)
    {
      Xf[dofs_per_node * a + c] = _Xf[dofs_per_node * node + c];
      uf[dofs_per_node * a + c] = u_fibre[dofs_per_node * node + c];
    }
  }
  for (int b = 0; b < _nm; ++b)
  {
    const std::size_t node = static_cast<std::size_t>(_cells[_nm * j + b]);
    for (int c = 0; c < 3; ++c)
      um[3 * b + c] = u_matrix[3 * node + c];
  }
}

double JunctionSet::assemble_vector(std::span<const double> u_fibre,
                                    std::span<const double> u_matrix, std::span<double> b_fibre,
                                    std::span<double> b_matrix) const
{
  if (b_fibre.size() != u_fibre.size() or b_matrix.size() != u_matrix.size())
    throw std::invalid_argument("JunctionSet.assemble_vector: b and u sizes differ");
  const std::size_t nq = dofs_per_node * _nf; // the fibre nodes' unknowns
  std::vector<double> Xf(nq), uf(nq), um(3 * _nm), r(nq + 3 * _nm);
  double energy = 0;
  for (std::size_t j = 0; j < size(); ++j)
  {
    gather(j, u_fibre, u_matrix, Xf, uf, um);
    std::fill(r.begin(), r.end(), 0.0);
    energy += fibre_matrix_junction(_k, _w[j], _nf, _xi[j], std::span(_c).subspan(2 * j, 2), Xf,
                                    uf, std::span(_Xm).subspan(3 * j, 3),
                                    std::span(_phi).subspan(_nm * j, _nm), um, {}, r, {});
    for (int a = 0; a < _nf; ++a)
      for (int c = 0; c < dofs_per_node; ++c)
        b_fibre[node_offset(_elem[_nf * j + a]) + c] += r[dofs_per_node * a + c];
    for (int b = 0; b < _nm; ++b)
      for (int c = 0; c < 3; ++c)
        b_matrix[3 * static_cast<std::size_t>(_cells[_nm * j + b]) + c]
            += r[dofs_per_node * _nf + 3 * b + c];
  }
  return energy;
}

void JunctionSet::assemble_matrix(Mat A, std::span<const std::int32_t> dofs_fibre,
                                  std::span<const std::int32_t> dofs_matrix)
{
  const int m = dofs_per_node * _nf + 3 * _nm;
  const std::size_t ng = _group.size() - 1;
  _indices.resize(ng * m);
  for (std::size_t g = 0; g < ng; ++g)
  {
    const std::size_t j = _order[_group[g]]; // any junction of the group
    std::int32_t* idx = _indices.data() + g * m;
    for (int a = 0; a < _nf; ++a)
      for (int c = 0; c < dofs_per_node; ++c)
        idx[dofs_per_node * a + c] = dofs_fibre[node_offset(_elem[_nf * j + a]) + c];
    for (int b = 0; b < _nm; ++b)
      for (int c = 0; c < 3; ++c)
        idx[dofs_per_node * _nf + 3 * b + c]
            = dofs_matrix[3 * static_cast<std::size_t>(_cells[_nm * j + b]) + c];
  }
  // the tangent is constant (quadratic energy): evaluate it at zero
  // displacement; the junctions of a group add into one block
  _insertion.add_blocks(
      A, _indices, m,
      [&](std::size_t g, std::span<double> K)
      {
        std::vector<double> Xf(dofs_per_node * _nf), zf(dofs_per_node * _nf, 0.0), zm(3 * _nm, 0.0);
        for (std::size_t i = _group[g]; i < _group[g + 1]; ++i)
        {
          const std::size_t j = _order[i];
          for (int a = 0; a < _nf; ++a)
            for (int c = 0; c < dofs_per_node; ++c)
              Xf[dofs_per_node * a + c] = _Xf[node_offset(_elem[_nf * j + a]) + c];
          fibre_matrix_junction(_k, _w[j], _nf, _xi[j], std::span(_c).subspan(2 * j, 2), Xf, zf,
                                std::span(_Xm).subspan(3 * j, 3),
                                std::span(_phi).subspan(_nm * j, _nm), zm, {}, {}, K);
        }
      });
}

std::vector<double> JunctionSet::gaps(std::span<const double> u_fibre,
                                      std::span<const double> u_matrix) const
{
  const std::size_t nq = dofs_per_node * _nf; // the fibre nodes' unknowns
  std::vector<double> out(3 * size()), Xf(nq), uf(nq), um(3 * _nm);
  for (std::size_t j = 0; j < size(); ++j)
  {
    gather(j, u_fibre, u_matrix, Xf, uf, um);
    fibre_matrix_junction(_k, _w[j], _nf, _xi[j], std::span(_c).subspan(2 * j, 2), Xf, uf,
                          std::span(_Xm).subspan(3 * j, 3),
                          std::span(_phi).subspan(_nm * j, _nm), um,
                          std::span(out).subspan(3 * j, 3), {}, {});
  }
  return out;
}

std::vector<double> JunctionSet::forces(std::span<const double> u_fibre,
                                        std::span<const double> u_matrix) const
{
  auto f = gaps(u_fibre, u_matrix);
  for (std::size_t j = 0; j < size(); ++j)
    for (int c = 0; c < 3; ++c)
      f[3 * j + c] *= _k * _w[j];
  return f;
}

std::vector<double> JunctionSet::total_force(std::span<const double> u_fibre,
                                             std::span<const double> u_matrix) const
{
  const auto f = forces(u_fibre, u_matrix);
  std::vector<double> total(3, 0.0);
  for (std::size_t j = 0; j < size(); ++j)
    for (int c = 0; c < 3; ++c)
      total[c] += f[3 * j + c];
  return total;
}
} // namespace textile::junction

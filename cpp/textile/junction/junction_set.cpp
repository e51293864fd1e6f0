#include "junction_set.h"
#include "fibre_matrix_junction.h"

#include <stdexcept>
#include <string>

namespace textile::junction
{
JunctionSet::JunctionSet(double k, int num_fibre_nodes, std::vector<std::int32_t> element_nodes,
                         std::vector<double> xi, std::vector<double> weight,
                         std::vector<double> X_fibre, std::vector<double> X_matrix,
                         std::vector<std::int32_t> cell_nodes, std::vector<double> phi)
    : _k(k), _nf(num_fibre_nodes),
      _nm(xi.empty() ? 0 : static_cast<int>(cell_nodes.size() / xi.size())),
      _elem(std::move(element_nodes)), _xi(std::move(xi)), _w(std::move(weight)),
      _Xf(std::move(X_fibre)), _Xm(std::move(X_matrix)), _cells(std::move(cell_nodes)),
      _phi(std::move(phi))
{
  const std::size_t n = _xi.size();
  if (!(_k > 0))
    throw std::invalid_argument("JunctionSet: stiffness must be positive");
  if (_nf != 2 and _nf != 3)
    throw std::invalid_argument("JunctionSet: num_fibre_nodes must be 2 or 3");
  if (_elem.size() != n * _nf or _w.size() != n or _Xm.size() != 3 * n
      or _cells.size() != n * _nm or _phi.size() != _cells.size() or _Xf.size() % 3)
    throw std::invalid_argument("JunctionSet: inconsistent array sizes");
  const std::size_t nfib = _Xf.size() / 3;
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
}

void JunctionSet::gather(std::size_t j, std::span<const double> u_fibre,
                         std::span<const double> u_matrix, std::span<double> Xf,
                         std::span<double> uf, std::span<double> um) const
{
  for (int a = 0; a < _nf; ++a)
  {
    const std::size_t node = static_cast<std::size_t>(_elem[_nf * j + a]);
    for (int c = 0; c < 3; ++c)
    {
      Xf[3 * a + c] = _Xf[3 * node + c];
      uf[3 * a + c] = u_fibre[9 * node + c];
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
  std::vector<double> Xf(3 * _nf), uf(3 * _nf), um(3 * _nm), r(3 * (_nf + _nm));
  double energy = 0;
  for (std::size_t j = 0; j < size(); ++j)
  {
    gather(j, u_fibre, u_matrix, Xf, uf, um);
    std::fill(r.begin(), r.end(), 0.0);
    energy += fibre_matrix_junction(_k, _w[j], _nf, _xi[j], Xf, uf,
                                    std::span(_Xm).subspan(3 * j, 3),
                                    std::span(_phi).subspan(_nm * j, _nm), um, {}, r, {});
    for (int a = 0; a < _nf; ++a)
      for (int c = 0; c < 3; ++c)
        b_fibre[9 * static_cast<std::size_t>(_elem[_nf * j + a]) + c] += r[3 * a + c];
    for (int b = 0; b < _nm; ++b)
      for (int c = 0; c < 3; ++c)
        b_matrix[3 * static_cast<std::size_t>(_cells[_nm * j + b]) + c]
            += r[3 * (_nf + b) + c];
  }
  return energy;
}

void JunctionSet::assemble_matrix(Mat A, std::span<const std::int32_t> dofs_fibre,
                                  std::span<const std::int32_t> dofs_matrix)
{
  const int m = 3 * (_nf + _nm);
  const std::size_t n = size();
  _indices.resize(n * m);
  for (std::size_t j = 0; j < n; ++j)
  {
    std::int32_t* idx = _indices.data() + j * m;
    for (int a = 0; a < _nf; ++a)
      for (int c = 0; c < 3; ++c)
        idx[3 * a + c] = dofs_fibre[9 * static_cast<std::size_t>(_elem[_nf * j + a]) + c];
    for (int b = 0; b < _nm; ++b)
      for (int c = 0; c < 3; ++c)
        idx[3 * (_nf + b) + c]
            = dofs_matrix[3 * static_cast<std::size_t>(_cells[_nm * j + b]) + c];
  }
  // the tangent is constant (quadratic energy): evaluate it at zero
  // displacement, where only the reference geometry enters
  _insertion.add_blocks(
      A, _indices, m,
      [&](std::size_t j, std::span<double> K)
      {
        std::vector<double> Xf(3 * _nf), zf(3 * _nf, 0.0), zm(3 * _nm, 0.0);
        for (int a = 0; a < _nf; ++a)
          for (int c = 0; c < 3; ++c)
            Xf[3 * a + c] = _Xf[3 * static_cast<std::size_t>(_elem[_nf * j + a]) + c];
        fibre_matrix_junction(_k, _w[j], _nf, _xi[j], Xf, zf, std::span(_Xm).subspan(3 * j, 3),
                              std::span(_phi).subspan(_nm * j, _nm), zm, {}, {}, K);
      });
}

std::vector<double> JunctionSet::gaps(std::span<const double> u_fibre,
                                      std::span<const double> u_matrix) const
{
  std::vector<double> out(3 * size()), Xf(3 * _nf), uf(3 * _nf), um(3 * _nm);
  for (std::size_t j = 0; j < size(); ++j)
  {
    gather(j, u_fibre, u_matrix, Xf, uf, um);
    fibre_matrix_junction(_k, _w[j], _nf, _xi[j], Xf, uf, std::span(_Xm).subspan(3 * j, 3),
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

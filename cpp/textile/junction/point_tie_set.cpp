#include "point_tie_set.h"
#include "../assembly/petsc_error.h"
#include "point_tie.h"

#include <stdexcept>

namespace textile::junction
{
PointTieSet::PointTieSet(double k, std::vector<std::int32_t> nodes,
                         std::vector<std::int32_t> cell_dofs, std::vector<double> phi)
    : _k(k), _n(nodes.empty() ? 0 : static_cast<int>(cell_dofs.size() / nodes.size())),
      _nodes(std::move(nodes)), _cells(std::move(cell_dofs)), _phi(std::move(phi))
{
  if (!(_k > 0))
    throw std::invalid_argument("PointTieSet: stiffness must be positive");
  if (_cells.size() != _nodes.size() * _n or _phi.size() != _cells.size())
    throw std::invalid_argument("PointTieSet: cell_dofs and phi need n entries per tie");
}

void PointTieSet::assemble_vector(std::span<const double> u_fibre,
                                  std::span<const double> u_solid, std::span<double> b_fibre,
                                  std::span<double> b_solid) const
{
  const double zero[3] = {0, 0, 0};
  std::vector<double> ucell(3 * _n), r(3 + 3 * _n);
  for (std::size_t t = 0; t < _nodes.size(); ++t)
  {
    for (int a = 0; a < _n; ++a)
      for (int c = 0; c < 3; ++c)
        ucell[3 * a + c] = u_solid[3 * static_cast<std::size_t>(_cells[_n * t + a]) + c];
    std::fill(r.begin(), r.end(), 0.0);
    point_tie(_k, std::span(_phi).subspan(_n * t, _n),
              u_fibre.subspan(9 * static_cast<std::size_t>(_nodes[t]), 3), ucell, zero, r, {});
    for (int c = 0; c < 3; ++c)
      b_fibre[9 * static_cast<std::size_t>(_nodes[t]) + c] += r[c];
    for (int a = 0; a < _n; ++a)
      for (int c = 0; c < 3; ++c)
        b_solid[3 * static_cast<std::size_t>(_cells[_n * t + a]) + c] += r[3 + 3 * a + c];
  }
}

void PointTieSet::assemble_matrix(Mat A, std::span<const std::int32_t> dofs_fibre,
                                  std::span<const std::int32_t> dofs_solid) const
{
  const double zero[3] = {0, 0, 0};
  const int m = 3 + 3 * _n;
  std::vector<double> ucell(3 * _n, 0.0), r(m), K(m * m);
  const std::vector<double> ua(3, 0.0);
  std::vector<PetscInt> idx(m);
  for (std::size_t t = 0; t < _nodes.size(); ++t)
  {
    std::fill(K.begin(), K.end(), 0.0);
    point_tie(_k, std::span(_phi).subspan(_n * t, _n), ua, ucell, zero, r, K); // linear: K(u) = K
    for (int c = 0; c < 3; ++c)
      idx[c] = dofs_fibre[9 * static_cast<std::size_t>(_nodes[t]) + c];
    for (int a = 0; a < _n; ++a)
      for (int c = 0; c < 3; ++c)
        idx[3 + 3 * a + c] = dofs_solid[3 * static_cast<std::size_t>(_cells[_n * t + a]) + c];
    assembly::check(MatSetValuesLocal(A, m, idx.data(), m, idx.data(), K.data(), ADD_VALUES),
                    "MatSetValuesLocal");
  }
}

std::vector<double> PointTieSet::total_force(std::span<const double> u_fibre,
                                             std::span<const double> u_solid) const
{
  // the residual on a tied node is k gap, the force its tie exerts on the solid
  std::vector<double> total(3, 0.0), bf(u_fibre.size(), 0.0), bs(u_solid.size(), 0.0);
  assemble_vector(u_fibre, u_solid, bf, bs);
  for (const auto node : _nodes)
    for (int c = 0; c < 3; ++c)
      total[c] += bf[9 * static_cast<std::size_t>(node) + c];
  return total;
}
} // namespace textile::junction

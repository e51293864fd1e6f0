#include "reference_geometry.h"
#include "../node_unknowns.h"
#include "shape_functions.h"

#include <array>
#include <stdexcept>

namespace textile::beam
{
void reference_points(const ElementRule& rule, const SectionQuadrature& section,
                      std::span<const double> X, std::span<ReferencePoint> out)
{
  using Vec3 = Eigen::Vector3d;
  const int nn = rule.num_nodes;
  if (X.size() != static_cast<std::size_t>(dofs_per_node * nn)
      or out.size() != num_points(rule, section))
    throw std::invalid_argument("reference_points: wrong array size");
  const std::size_t nq = section.size();
  for (std::size_t g = 0; g < rule.axial.points.size(); ++g)
  {
    std::array<double, 3> n, dn;
    lagrange(nn, rule.axial.points[g], n, dn);
    Vec3 dX0 = Vec3::Zero(), G1 = Vec3::Zero(), G2 = Vec3::Zero(), dG1 = Vec3::Zero(),
         dG2 = Vec3::Zero();
    for (int a = 0; a < nn; ++a)
    {
      const double* node = X.data() + dofs_per_node * a;
      const Eigen::Map<const Vec3> X0a(node), G1a(node + 3), G2a(node + 6);
      dX0 += dn[a] * X0a;
      G1 += n[a] * G1a;
      G2 += n[a] * G2a;
      dG1 += dn[a] * G1a;
      dG2 += dn[a] * G2a;
    }
    const Vec3 e3 = dX0.normalized();
    const Vec3 e1 = (G1 - G1.dot(e3) * e3).normalized();
    const Vec3 e2 = e3.cross(e1);
    Eigen::Matrix3d Q;
    Q << e1, e2, e3;
    for (std::size_t i = 0; i < nq; ++i)
    {
      Eigen::Matrix3d Fref;
      Fref << G1, G2, dX0 + section.xi1[i] * dG1 + section.xi2[i] * dG2;
      const double det = Fref.determinant();
      if (!(det > 0))
        throw std::runtime_error("beam element: degenerate or inverted reference geometry "
                                 "(section vectors must be independent and not along the "
                                 "tangent)");
      ReferencePoint& p = out[g * nq + i];
      p.B = Fref.inverse() * Q;
      p.dV = rule.axial.weights[g] * section.weights[i] * det;
    }
  }
}
} // namespace textile::beam

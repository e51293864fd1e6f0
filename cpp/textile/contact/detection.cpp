#include "detection.h"

#include <cmath>

namespace textile::contact
{
Detection detect(const Centrelines& c, const SectionVectors& g, double delta_factor,
                 double self_exclusion, double spacing, double parallel_angle)
{
  Detection d;
  d.zones = find_proximity_zones(c, delta_factor, self_exclusion);
  for (std::size_t z = 0; z < d.zones.size(); ++z)
  {
    for (auto& p : contact_points(c, g, d.zones[z], spacing, parallel_angle, delta_factor))
    {
      d.points.push_back(p);
      d.zone_of_point.push_back(static_cast<int>(z));
    }
  }
  return d;
}

ContactElementState make_element(const Centrelines& c, const ContactPoint& p, int zone,
                                 const Eigen::Vector3d& normal, double penalty, double g_r,
                                 const RegularizedCoulomb& friction,
                                 const Eigen::Vector3d& elastic_slip, std::span<const double> q)
{
  ContactElementState e;
  e.fibre_i = p.fibre_i;
  e.fibre_j = p.fibre_j;
  e.s_i = p.s_i;
  e.s_j = p.s_j;
  e.zone = zone;
  e.crossing = p.crossing;
  e.length = p.length;
  const int nn = c.order + 1;
  e.particle_i = {nn, element_of(c, p.fibre_i, p.s_i, e.nodes_i), p.xi1_i, p.xi2_i,
                  c.radius[p.fibre_i]};
  e.particle_j = {nn, element_of(c, p.fibre_j, p.s_j, e.nodes_j), p.xi1_j, p.xi2_j,
                  c.radius[p.fibre_j]};
  e.normal = normal;
  e.penalty = penalty;
  e.regularization = g_r;
  e.friction = friction;
  // the stick point that reproduces the carried elastic slip
  std::vector<double> xi, xj;
  for (int a = 0; a < nn; ++a)
    for (int k = 0; k < 9; ++k)
    {
      xi.push_back(q[9 * e.nodes_i[a] + k]);
      xj.push_back(q[9 * e.nodes_j[a] + k]);
    }
  const Eigen::Vector3d delta = particle_position(e.particle_i, xi)
                                - particle_position(e.particle_j, xj);
  const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - normal * normal.transpose();
  e.stick = delta - P * elastic_slip;
  e.result.delta = delta;
  return e;
}
} // namespace textile::contact

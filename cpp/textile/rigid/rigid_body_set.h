// All rigid bodies of a scene and their couplings, assembled together.
//
// Unknowns (local arrays of the stacked layout, textile/layout.py):
//  - fibre nodes: 9 per local node [x0, g1, g2] displacements, reference X;
//  - bodies: 6 per body [u, theta] (centre displacement, incremental
//    rotation vector, rotation.h), reference centres C;
//  - multipliers: 9 per coupled section, 3 per coupled point.
// Each coupling ties one fibre node to one body (rigid_coupling.h). Body
// loads: dead forces on u and moments (fixed in space) on theta, scaled by
// the load factor.
#pragma once

#include "rigid_coupling.h"

#include <petscmat.h>

#include <cstdint>
#include <span>
#include <vector>

namespace textile::rigid
{

struct Coupling
{
  int body = 0;                ///< local body index
  std::int32_t node = 0;       ///< local fibre node
  std::int32_t multiplier = 0; ///< local index of the first multiplier row
  CouplingBase base;           ///< in the body's frame at the step start
  double scale_position = 1;   ///< s of the x0 rows (force/length)
  double scale_section = 1;    ///< s of the g1, g2 rows (force length)
};

/// Resultant force and moment (about the current centre) that a body
/// exerts on what it holds.
struct BodyReaction
{
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();
};

class RigidBodySet
{
public:
  std::vector<Coupling> couplings;
  std::vector<Eigen::Vector3d> centres; ///< reference centres C, per local body
  std::vector<Eigen::Vector3d> forces;  ///< current dead force, per owned body
  std::vector<Eigen::Vector3d> moments; ///< current moment, per owned body

  /// b += residual of the couplings and body loads (local arrays).
  void assemble_vector(std::span<const double> X,
                       std::span<const double> u_fibre, std::span<const double> u_body,
                       std::span<const double> lambda, std::span<double> b_fibre,
                       std::span<double> b_body, std::span<double> b_lambda) const;

  /// A += tangent; dofs_*: stacked local index of each local unknown, -1
  /// where constrained.
  void assemble_matrix(Mat A, std::span<const double> X,
                       std::span<const double> u_fibre, std::span<const double> u_body,
                       std::span<const double> lambda, std::span<const std::int32_t> dofs_fibre,
                       std::span<const std::int32_t> dofs_body,
                       std::span<const std::int32_t> dofs_lambda) const;

  /// Per local body: what it exerts on the fibres it holds (this rank's
  /// couplings only; sum over ranks).
  std::vector<BodyReaction> reactions(std::span<const double> X, std::span<const double> u_fibre,
                                      std::span<const double> u_body,
                                      std::span<const double> lambda) const;

  /// True when a body carries a moment: the tangent is then not symmetric.
  bool has_moments() const;

private:
  template <typename Visit>
  void each(std::span<const double> X, std::span<const double> u_fibre,
            std::span<const double> u_body, std::span<const double> lambda, bool tangent,
            Visit&& visit) const;
};

} // namespace textile::rigid

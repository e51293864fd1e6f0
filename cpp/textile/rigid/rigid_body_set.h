// All rigid bodies of a scene and their couplings, assembled together.
//
// Unknowns (local arrays of the stacked layout, textile/system/layout.py):
//  - fibre nodes: 9 per local node [x0, g1, g2] displacements, reference X;
//  - bodies: 6 per body [u, theta] (centre displacement, incremental
//    rotation vector, rotation.h), reference centres C;
//  - nodes of an elastic block (matrix): 3 displacements per local node,
//    reference positions given per node;
//  - multipliers: one per constraint row (9 per held section, 3 per held
//    point, one per row of a sliding coupling).
// Each coupling ties one fibre node or one block node to one body, fully
// (rigid_coupling.h) or along body-fixed directions (sliding_coupling.h).
// Every coupling is assembled by the one rank that owns its node (the
// caller passes owned nodes only), so a ghost is never coupled twice. Body
// loads: dead forces on u and moments (fixed in space) on theta, scaled by
// the load factor.
#pragma once

#include "rigid_coupling.h"
#include "sliding_coupling.h"

#include <petscmat.h>

#include <cstdint>
#include <span>
#include <vector>

namespace textile::rigid
{

/// Which unknowns a coupling holds.
enum class Holds : int
{
  fibre = 0, ///< a fibre node (9 unknowns; base.section: all 9, else x0)
  block = 1  ///< an elastic block node (3 displacements)
};

struct Coupling
{
  int body = 0;                ///< local body index
  std::int32_t node = 0;       ///< local fibre node or local block node
  std::int32_t multiplier = 0; ///< local index of the first multiplier row
  Holds holds = Holds::fibre;
  CouplingBase base;           ///< in the body's frame at the step start
  std::vector<SlidingRow> sliding; ///< empty: fully held; else these rows only
  double scale_position = 1;   ///< s of the x0 rows (force/length)
  double scale_section = 1;    ///< s of the g1, g2 rows (force length)

  int unknowns() const { return base.rows(); }
  int rows() const { return sliding.empty() ? base.rows() : static_cast<int>(sliding.size()); }
};

/// The local arrays of the block whose nodes bodies hold (empty if none):
/// reference positions and displacements, 3 per local node.
struct BlockArrays
{
  std::span<const double> X, u;
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
                       std::span<const double> lambda, BlockArrays block,
                       std::span<double> b_fibre, std::span<double> b_body,
                       std::span<double> b_lambda, std::span<double> b_block) const;

  /// A += tangent; dofs_*: stacked local index of each local unknown, -1
  /// where constrained.
  void assemble_matrix(Mat A, std::span<const double> X,
                       std::span<const double> u_fibre, std::span<const double> u_body,
                       std::span<const double> lambda, BlockArrays block,
                       std::span<const std::int32_t> dofs_fibre,
                       std::span<const std::int32_t> dofs_body,
                       std::span<const std::int32_t> dofs_lambda,
                       std::span<const std::int32_t> dofs_block) const;

  /// Per local body: what it exerts on the fibres and block nodes it holds
  /// (this rank's couplings only; sum over ranks).
  std::vector<BodyReaction> reactions(std::span<const double> X, std::span<const double> u_fibre,
                                      std::span<const double> u_body,
                                      std::span<const double> lambda, BlockArrays block) const;

  /// True when a body carries a moment: the tangent is then not symmetric.
  bool has_moments() const;

private:
  template <typename Visit>
  void each(std::span<const double> X, std::span<const double> u_fibre,
            std::span<const double> u_body, std::span<const double> lambda, BlockArrays block,
            bool tangent, Visit&& visit) const;
};

} // namespace textile::rigid

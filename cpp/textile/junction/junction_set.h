// All fibre-matrix junctions of an effect, assembled together (no loop per
// junction in Python).
#pragma once

#include "../assembly/petsc_insert.h"

#include <petscmat.h>

#include <cstdint>
#include <span>
#include <vector>

namespace textile::junction
{

/// A batch of junctions (fibre_matrix_junction.h) with the same stiffness
/// per unit length k, the same fibre element (num_fibre_nodes = 2 or 3) and
/// the same number of matrix cell nodes n_m (taken from the data).
///
/// Unknown layouts: fibre field 9 per local node (x0, g1, g2); matrix field
/// 3 per local node. Each junction's fibre particle is at section
/// coordinates (c1, c2) (0, 0 on the centre line), so its fibre side is a
/// linear combination of the element nodes' 9 unknowns.
///
/// The tangent is assembled one block per distinct (fibre element, matrix
/// cell) pair: the junctions sharing both (e.g. the particles of a section
/// that fall in the same cell) are summed into one block.
class JunctionSet
{
public:
  /// @param k               stiffness per unit fibre length (N/m^2), > 0
  /// @param num_fibre_nodes nodes of a fibre element (2 or 3)
  /// @param element_nodes   local fibre nodes of each junction's element,
  ///                        num_fibre_nodes per junction
  /// @param xi              each particle's coordinate in its element, [-1, 1]
  /// @param section         each particle's section coordinates (c1, c2), 2 each
  /// @param weight          fibre length each particle stands for (> 0)
  /// @param X_fibre         reference unknowns of the local fibre nodes (9 each:
  ///                        x0, g1, g2)
  /// @param X_matrix        reference matrix point of each junction (3 each)
  /// @param cell_nodes      local matrix nodes (block dofs) of each
  ///                        junction's cell, n_m per junction
  /// @param phi             their basis values at X_matrix, n_m per junction
  JunctionSet(double k, int num_fibre_nodes, std::vector<std::int32_t> element_nodes,
              std::vector<double> xi, std::vector<double> section, std::vector<double> weight,
              std::vector<double> X_fibre,
              std::vector<double> X_matrix, std::vector<std::int32_t> cell_nodes,
              std::vector<double> phi);

  std::size_t size() const { return _xi.size(); }
  /// Tangent blocks: distinct (fibre element, matrix cell) pairs.
  std::size_t num_blocks() const { return _group.size() - 1; }
  int num_cell_nodes() const { return _nm; }
  int num_fibre_nodes() const { return _nf; }
  double stiffness() const { return _k; }

  /// b_fibre (9 per local fibre node) and b_matrix (3 per local matrix
  /// node) += residual of every junction at u_fibre, u_matrix; returns the
  /// stored energy.
  double assemble_vector(std::span<const double> u_fibre, std::span<const double> u_matrix,
                         std::span<double> b_fibre, std::span<double> b_matrix) const;

  /// A += tangent (constant), through the project's block insertion;
  /// dofs_*: stacked local index of each local unrolled unknown, -1 where
  /// constrained (skipped). Assemble A afterwards.
  void assemble_matrix(Mat A, std::span<const std::int32_t> dofs_fibre,
                       std::span<const std::int32_t> dofs_matrix);

  /// Gap x_f - x_m of every junction (3 each).
  std::vector<double> gaps(std::span<const double> u_fibre,
                           std::span<const double> u_matrix) const;

  /// Force k w (x_f - x_m) every junction exerts on the matrix (3 each; the
  /// fibre receives the opposite).
  std::vector<double> forces(std::span<const double> u_fibre,
                             std::span<const double> u_matrix) const;

  /// Sum of forces(), (3,).
  std::vector<double> total_force(std::span<const double> u_fibre,
                                  std::span<const double> u_matrix) const;

private:
  void gather(std::size_t j, std::span<const double> u_fibre, std::span<const double> u_matrix,
              std::span<double> Xf, std::span<double> uf, std::span<double> um) const;

  double _k;
  int _nf, _nm;
  std::vector<std::int32_t> _elem;
  std::vector<double> _xi, _c, _w, _Xf, _Xm;
  std::vector<std::int32_t> _cells;
  std::vector<double> _phi;
  // junctions grouped by (element nodes, cell nodes): group g holds
  // _order[_group[g], _group[g + 1])
  std::vector<std::size_t> _order, _group;
  assembly::BlockInsertion _insertion;
  std::vector<std::int32_t> _indices; // block indices of the last assembly
};

} // namespace textile::junction

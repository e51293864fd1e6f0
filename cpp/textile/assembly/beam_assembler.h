// Assembly of the beam elasticity of all fibre elements held by this rank.
#pragma once

#include "../beam/beam_element.h"
#include "petsc_insert.h"

#include <petscmat.h>

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace textile::assembly
{

/// Elements of one MPI rank, with their reference geometry.
///
/// Nodes are numbered locally (owned then ghost, as in the beam field's
/// index map); each holds 9 unknowns [x0, g1, g2]. The unknowns passed in
/// are displacements u = x - X.
class BeamAssembler
{
public:
  /// @param rule          element type and axial quadrature (all elements)
  /// @param connectivity  local node indices, num_elements x num_nodes
  /// @param element_group index into materials/sections per element
  /// @param materials     one per group
  /// @param sections      one per group (radius, quadrature)
  /// @param X             reference unknowns, 9 per local node
  /// @param element_number number of each element within its fibre, for
  ///                      error messages (empty: the local element index)
  BeamAssembler(beam::ElementRule rule, std::vector<std::int32_t> connectivity,
                std::vector<std::int32_t> element_group, std::vector<beam::Material> materials,
                std::vector<beam::SectionQuadrature> sections, std::vector<double> X,
                std::vector<std::int32_t> element_number = {});

  std::size_t num_elements() const { return _group.size(); }
  int num_nodes_per_element() const { return _rule.num_nodes; }

  /// Threads the element loops of assemble_vector and assemble_matrix may
  /// use (default 1; fewer when there are few elements). The calling thread
  /// adds the element forces and blocks in element order: the results do
  /// not depend on the number of threads.
  int num_threads() const { return _num_threads; }
  void set_num_threads(int n);

  /// b += internal force (9 per local node); returns the stored energy of
  /// this rank's elements. A folded element (det F <= 0 at a quadrature
  /// point) throws textile::GeometryError naming the element and its fibre
  /// (group); so do assemble_matrix and fields.
  double assemble_vector(std::span<const double> u, std::span<double> b) const;

  /// A += tangent. dofs[9*i + k] is the matrix-local index of unknown k of
  /// local node i, or -1 where the dof is constrained. du: empty for the
  /// exact tangent, or the last Newton update (9 per local node) for the MIP
  /// Newton tangent (see beam::element_residual_tangent), or k such
  /// updates one after another with their k weights du_weights.
  void assemble_matrix(Mat A, std::span<const double> u, std::span<const std::int32_t> dofs,
                       std::span<const double> du = {},
                       std::span<const double> du_weights = {}) const;

  /// Element-averaged section strain and stress, 12 values per element
  /// (Voigt strain then stress).
  std::vector<double> fields(std::span<const double> u) const;

private:
  /// Element e's entries of a nodal array (9 per local node).
  template <typename T>
  void gather(std::size_t e, std::span<const T> values, std::span<T> out) const;
  /// Element e's current unknowns X + u.
  void current(std::size_t e, std::span<const double> u, std::span<double> xe) const;
  /// Reference data of element e's quadrature points.
  std::span<const beam::ReferencePoint> reference(std::size_t e) const;
  /// Threads for an element loop: num_threads, fewer for few elements.
  int threads_for_elements() const;
  /// "element <number> of fibre <group>", for error messages.
  std::string describe(std::size_t e) const;
  /// kernel() for element e; a GeometryError it throws gets the element's
  /// description prepended.
  template <typename Kernel>
  auto on_element(std::size_t e, Kernel&& kernel) const;

  beam::ElementRule _rule;
  std::vector<std::int32_t> _conn, _group, _number;
  std::vector<beam::Material> _materials;
  std::vector<beam::SectionQuadrature> _sections;
  std::vector<double> _X;
  // reference data of every element's quadrature points, computed once;
  // element e's start at _ref_offset[e]
  std::vector<beam::ReferencePoint> _ref;
  std::vector<std::size_t> _ref_offset;
  // positions of the element blocks in the matrix (a cache: found again
  // when the matrix or its pattern changes)
  mutable BlockInsertion _insertion;
  int _num_threads = 1;
};

} // namespace textile::assembly

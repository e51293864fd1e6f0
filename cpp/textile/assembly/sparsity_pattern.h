// The nonzero pattern of a system matrix whose couplings grow with the
// contact set, built directly in compressed rows.
//
// Contact couples unknowns that change from one detection pass to the next
// and that need not be local to one rank, so their entries cannot be
// declared in the dolfinx sparsity pattern built once. When the couplings
// change, the system matrix is rebuilt: the base pattern (beams, matrix
// block, junctions) plus the new couplings, preallocated exactly, so
// assembly never reallocates.
//
// PETSc's MATPREALLOCATOR does this through a hash set of (row, column)
// pairs and then inserts the zeros row by row, several times slower
// (benchmarks/README.md, "Matrix rebuilds as compressed rows"). Here the
// base's rows are read once and kept; each
// rebuild appends the declared columns to their rows, sorts and merges
// each row, and hands PETSc the finished rows in one call
// (Mat{Seq,MPI}AIJSetPreallocationCSR).
//
// Collective: create_matrix is called by every rank of the base's
// communicator together; rows another rank owns may be declared anywhere
// and are sent to their owner.
#pragma once

#include <petscmat.h>

#include <cstdint>
#include <span>
#include <vector>

namespace textile::assembly
{

class SparsityPattern
{
public:
  /// The pattern of `base` (an assembled AIJ matrix addressed by global
  /// indices): its owned rows, read once (no reference to it is kept).
  explicit SparsityPattern(Mat base);

  /// Declare the dense block A[rows, cols] (global indices; negative ones
  /// are skipped; rows of any rank).
  void add(std::span<const std::int32_t> rows, std::span<const std::int32_t> cols);

  /// A new matrix of the type, layout and local-to-global maps of `base`
  /// (the matrix the pattern was read from, or one of its layout) holding
  /// base's pattern as read plus every declared entry, all zero,
  /// assembled; the caller owns it.
  /// An entry outside the pattern later costs a reallocation, not an
  /// error. Forgets the declared entries (the base pattern stays), so one
  /// object serves every rebuild. Collective.
  Mat create_matrix(Mat base);

  /// Entries of base's owned rows.
  std::size_t base_size() const { return base_cols_.size(); }

private:
  PetscInt row_begin_ = 0, row_end_ = 0;
  std::vector<PetscInt> ranges_;             // first row of each rank, and the end
  std::vector<PetscInt> base_start_, base_cols_; // base's owned rows (CSR, sorted)
  std::vector<std::vector<PetscInt>> added_; // declared columns of each owned row
  std::vector<std::vector<PetscInt>> sent_;  // per rank: row, count, columns...
};

} // namespace textile::assembly

// Contact tangents summed per pair of fibre nodes, inserted into PETSc one
// block row at a time.
//
// A contact element couples the nodes of an element of fibre i with those
// of an element of fibre j (6 nodes of 9 unknowns for quadratic elements).
// A line contact puts 2 to 4 elements on each pair of fibre elements and
// neighbouring pairs share nodes, so inserting each element's dense
// 54 x 54 block value by value (a column search per value) costs many
// times the kernel that computes it. Here the element tangents are summed
// into 9 x 9 blocks, one per (row node, column node), in a buffer laid out
// once per element set (the set is fixed during a Newton solve); each block
// row then enters the matrix in one MatSetValues call with its columns
// sorted, so PETSc finds the slots in one forward scan per row. Only the
// blocks something was added to are inserted: open elements neither
// compute nor insert anything, and couplings the matrix was not
// preallocated for are never touched by them.
//
// Insertion. Even with sorted columns, MatSetValues searches every value's
// slot in its row (a binary search per value): for the node blocks of a
// bundle that is several times the element kernels' cost. For the AIJ
// types (seqaij, mpiaij), the slot of every value of a block in the
// matrix's own value arrays is therefore located once per matrix pattern
// (the matrix and its nonzero state; MatGetRowIJ, MatMPIAIJGetSeqAIJ), and
// each summed block is added straight into those arrays. Blocks of rows
// owned by another rank are sent to it and added there the same way
// (assembly/off_rank_blocks.h: collective, so insert() is too on an mpiaij
// matrix); blocks outside the pattern and other matrix types go through
// MatSetValues (which allocates as PETSc does).
//
// Works for any AIJ matrix addressed by global indices (a block size of 9
// is not assumed: a scene's matrix may stack fields of block sizes 9 and 3).
#pragma once

#include "../assembly/off_rank_blocks.h"
#include "../assembly/sparsity_pattern.h"

#include <petscmat.h>

#include <cstdint>
#include <span>
#include <vector>

namespace textile::contact
{

class NodeBlockMatrix
{
public:
  /// Lay out the blocks of a set of elements: element e has the nodes
  /// nodes[offsets[e]], ..., nodes[offsets[e + 1] - 1] (global fibre
  /// nodes; the row and column order of its tangent), and unknown k of
  /// node n has the global index dofs[9 n + k] (-1: constrained, skipped).
  /// Clears anything added before.
  void build(std::span<const std::size_t> offsets, std::span<const std::int64_t> nodes,
             std::span<const std::int32_t> dofs);

  /// Whether the layout was built for these global indices.
  bool built_for(std::span<const std::int32_t> dofs) const;

  /// Number of elements and of distinct node-pair blocks of the layout.
  std::size_t num_elements() const { return element_start_.empty() ? 0 : element_start_.size() - 1; }
  std::size_t num_blocks() const { return col_node_.size(); }

  /// Add element e's tangent (row-major, 9 n x 9 n for its n nodes, in the
  /// order given to build) to its blocks.
  void add(std::size_t e, std::span<const double> K);

  /// A[rows, cols] += the blocks added since the last call (ADD_VALUES,
  /// global indices); then clears them. Collective on an mpiaij matrix
  /// (every rank of its communicator calls it, with or without blocks).
  void insert(Mat A);

  /// Blocks of other ranks' rows inserted so far: sent to their owners
  /// (added in place there), and stashed by MatSetValues (other types).
  struct OffRankCounts
  {
    std::size_t sent = 0, stashed = 0;
  };
  const OffRankCounts& off_rank_counts() const { return off_rank_counts_; }

  /// Declare every block of the layout in a pattern being built.
  void insert_pattern(assembly::SparsityPattern& pattern) const;

private:
  std::vector<std::int32_t> dofs_;          // the global indices it was built for
  std::vector<std::int64_t> row_node_;      // block rows
  std::vector<std::size_t> row_start_;      // blocks of row r: [row_start_[r], row_start_[r + 1])
  std::vector<std::int64_t> col_node_;      // column node of each block, sorted by index in a row
  std::vector<std::size_t> element_start_;  // element e's block slots start here
  std::vector<std::int32_t> element_block_; // n x n per element (row-major), -1: constrained node
  std::vector<int> element_nodes_;          // n of each element
  std::vector<double> values_;              // 81 per block, row-major
  std::vector<std::int32_t> block_row_;     // row of each block
  std::vector<char> block_touched_, row_touched_;
  std::vector<std::int32_t> touched_;       // blocks added to since the last insertion
  mutable std::vector<std::int32_t> cols_;  // scratch of one block row
  mutable std::vector<double> row_values_;

  /// Slots of the blocks' values in an AIJ matrix's value arrays.
  struct MatrixSlots
  {
    Mat matrix = nullptr;
    PetscObjectState nonzero_state = -1;
    bool direct = false;                  // an AIJ type whose arrays are used
    bool parallel = false;                // mpiaij: diagonal and off-diagonal parts
    std::size_t diagonal_size = 0;        // entries of the diagonal part (mpiaij)
    std::vector<std::int64_t> position;   // 81 per block: diagonal part [0, diagonal_size),
                                          // off-diagonal part after it; -1: constrained
    std::vector<char> block_direct;       // rows owned here, entries inside the pattern
    std::vector<char> block_rows_contiguous; // each row's 9 slots side by side
    std::vector<char> row_owned;          // block rows owned here (all of them: not mpiaij)
    std::vector<std::int32_t> off_rank;   // blocks of rows owned elsewhere (mpiaij)
  };
  MatrixSlots slots_;
  assembly::OffRankBlocks off_rank_; // off_rank blocks, located by their owners
  OffRankCounts off_rank_counts_;

  /// Hand the off-rank blocks to their owners to locate (collective).
  void setup_off_rank(Mat A);

  /// Locate the slots of every block of the layout in A (AIJ types).
  void locate(Mat A);

  /// One MatSetValues for block row r: its touched blocks' values.
  void insert_row(Mat A, std::size_t r) const;
};

} // namespace textile::contact

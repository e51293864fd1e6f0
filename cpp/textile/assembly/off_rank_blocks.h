// Square blocks of rows another rank owns, summed by that rank straight
// into its matrix arrays instead of through PETSc's stash.
//
// MatSetValues on another rank's rows stashes every value with its indices;
// MatAssemblyEnd sends them and the owner inserts them with MatSetValues,
// a binary search a value. For the contact tangent of a fabric whose warp
// and weft sit on different ranks, every crossing couples the two ranks:
// about 18 million stashed values a tangent, ~3 s of each Newton iteration
// on the 336-fibre sample (benchmarks/README.md). The blocks of an element
// set do not change during a Newton solve, so here the owners locate every
// entry of the blocks they will receive once, and each assembly sends only
// the values (one flag a block, then the values of the blocks that have
// any), which the owners add at the located slots.
//
// Collective: setup and add are called by every rank of the matrix's
// communicator together, with the blocks each holds (none is fine).
#pragma once

#include <petscmat.h>

#include <cstdint>
#include <span>
#include <vector>

namespace textile::assembly
{

class OffRankBlocks
{
public:
  /// Blocks of bs x bs values: block b has the global rows
  /// rows[bs b, bs (b + 1)) and columns cols[bs b, bs (b + 1)) (negative:
  /// skipped); its non-negative rows all belong to one other rank. Each
  /// owner locates the entries in A (an mpiaij matrix with its final
  /// pattern); entries outside the pattern make their block go through
  /// MatSetValues on its owner (rows owned there: nothing stashed).
  void setup(Mat A, int bs, std::span<const std::int32_t> rows,
             std::span<const std::int32_t> cols);

  /// Number of blocks given to setup.
  std::size_t num_blocks() const { return _num_blocks; }

  /// A[rows_b, cols_b] += the values of every block b with touched[w_b],
  /// w_b = where[b]: bs x bs row-major at values[bs^2 w_b]. The owners add
  /// them into their arrays (or MatSetValues, see setup). Returns the
  /// number of blocks received here.
  std::size_t add(Mat A, std::span<const std::int32_t> where, std::span<const char> touched,
                  std::span<const double> values);

private:
  int _bs = 0;
  std::size_t _num_blocks = 0;
  // sender: blocks in destination order, and how many go to each rank
  std::vector<std::int32_t> _order;
  std::vector<int> _send_blocks;
  // receiver: blocks from each rank, and for each received block its
  // bs^2 slots (-1 skipped, AijPattern numbering) or, when it lies
  // partly outside the pattern, its rows and columns for MatSetValues
  std::vector<int> _recv_blocks;
  std::vector<std::int64_t> _slots;
  std::vector<char> _outside;
  std::vector<std::int32_t> _recv_rows, _recv_cols;
  std::int64_t _diagonal_size = 0;
  // scratch
  std::vector<char> _flags_out, _flags_in;
  std::vector<double> _values_out, _values_in;
};

} // namespace textile::assembly

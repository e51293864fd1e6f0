// The single place where local blocks enter a PETSc matrix.
#pragma once

#include <petscmat.h>

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

namespace textile::assembly
{

/// A[rows, cols] += values (row-major), in the matrix's local numbering
/// (its local-to-global map). Negative indices are skipped by PETSc: that
/// is how constrained (Dirichlet) dofs are kept out of the tangent.
/// Throws std::runtime_error on a PETSc error.
void add_block(Mat A, std::span<const std::int32_t> rows, std::span<const std::int32_t> cols,
               std::span<const double> values);

/// A[rows[k], cols[k]] += values[k] for each k (local indices; an entry
/// with a negative index is skipped): scattered entries, one per k.
void add_entries(Mat A, std::span<const std::int32_t> rows, std::span<const std::int32_t> cols,
                 std::span<const double> values);

/// A[i, i] += value for every local index i in rows (negative skipped).
void add_diagonal(Mat A, std::span<const std::int32_t> rows, double value);

/// Adds many square blocks with fixed local indices (element matrices).
///
/// MatSetValuesLocal searches every entry's column in its row, about 20 ns
/// an entry: a 27 x 27 element block cost more than the element kernel.
/// Once A is assembled with its final pattern, this finds the position of
/// every block entry in the (MPI)AIJ matrix's value arrays once, and adds
/// later blocks there directly. The positions are found again when A (its
/// PETSc object id), its nonzero pattern or the indices change. Matrices
/// of other types or not yet assembled, and the rows of a block owned by
/// another rank, go through add_block. As with add_block, assemble A
/// afterwards.
class BlockInsertion
{
public:
  /// For every block b: fill(b, values) adds its row-major values into a
  /// zeroed buffer of block_size^2, then A[idx_b, idx_b] += values with
  /// idx_b = indices[b * block_size, (b + 1) * block_size) (local indices,
  /// negative: skipped). With num_threads > 1, fill runs on that many
  /// threads (it must be thread-safe) and the calling thread adds the
  /// blocks in block order while the others compute the next ones: the
  /// matrix does not depend on the number of threads. An exception from
  /// fill propagates after A's value arrays are handed back.
  void add_blocks(Mat A, std::span<const std::int32_t> indices, int block_size,
                  const std::function<void(std::size_t, std::span<double>)>& fill,
                  int num_threads = 1);

private:
  bool matches(Mat A, std::span<const std::int32_t> indices, int block_size) const;
  void find_positions(Mat A, std::span<const std::int32_t> indices, int block_size);

  // what the positions were found for
  PetscObjectId _id = -1;
  PetscObjectState _nonzero_state = 0;
  int _block_size = 0;
  std::vector<std::int32_t> _indices;
  bool _direct = false; // positions valid (else every block through add_block)
  std::int64_t _diagonal_size = 0; // AijPattern's, for AijValues
  // per block entry: its AijPattern slot, or -1 (skipped, or a row of
  // another rank)
  std::vector<std::int64_t> _position;
  // blocks with rows owned by another rank: those rows (others -1), added
  // through add_block
  std::vector<std::size_t> _remote_blocks;
  std::vector<std::int32_t> _remote_rows;
};

} // namespace textile::assembly

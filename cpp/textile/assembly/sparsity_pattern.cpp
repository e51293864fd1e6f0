#include "sparsity_pattern.h"
#include "petsc_error.h"

#include <algorithm>
#include <stdexcept>

namespace textile::assembly
{
SparsityPattern::SparsityPattern(Mat base)
{
  check(MatGetOwnershipRange(base, &row_begin_, &row_end_), "MatGetOwnershipRange");
  const PetscInt* ranges;
  check(MatGetOwnershipRanges(base, &ranges), "MatGetOwnershipRanges");
  MPI_Comm comm;
  check(PetscObjectGetComm(reinterpret_cast<PetscObject>(base), &comm), "PetscObjectGetComm");
  int size;
  MPI_Comm_size(comm, &size);
  ranges_.assign(ranges, ranges + size + 1);
  sent_.resize(size);
  const PetscInt m = row_end_ - row_begin_;
  added_.resize(m);
  base_start_.assign(1, 0);
  for (PetscInt row = row_begin_; row < row_end_; ++row)
  {
    PetscInt ncols;
    const PetscInt* cols;
    check(MatGetRow(base, row, &ncols, &cols, nullptr), "MatGetRow");
    base_cols_.insert(base_cols_.end(), cols, cols + ncols);
    check(MatRestoreRow(base, row, &ncols, &cols, nullptr), "MatRestoreRow");
    base_start_.push_back(static_cast<PetscInt>(base_cols_.size()));
  }
}

void SparsityPattern::add(std::span<const std::int32_t> rows, std::span<const std::int32_t> cols)
{
  for (const std::int32_t row : rows)
  {
    if (row < 0)
      continue;
    if (row >= row_begin_ and row < row_end_)
    {
      auto& target = added_[row - row_begin_];
      for (const std::int32_t col : cols)
        if (col >= 0)
          target.push_back(col);
      continue;
    }
    // another rank's row: row, count, columns, for its owner
    const auto owner = std::upper_bound(ranges_.begin(), ranges_.end(), row) - ranges_.begin() - 1;
    auto& target = sent_.at(owner);
    target.push_back(row);
    target.push_back(0);
    const std::size_t count_at = target.size() - 1;
    for (const std::int32_t col : cols)
      if (col >= 0)
        target.push_back(col);
    target[count_at] = static_cast<PetscInt>(target.size() - count_at - 1);
  }
}

Mat SparsityPattern::create_matrix(Mat base)
{
  MPI_Comm comm;
  check(PetscObjectGetComm(reinterpret_cast<PetscObject>(base), &comm), "PetscObjectGetComm");
  PetscInt r0, r1;
  check(MatGetOwnershipRange(base, &r0, &r1), "MatGetOwnershipRange");
  if (r0 != row_begin_ or r1 != row_end_)
    throw std::invalid_argument("SparsityPattern::create_matrix: base has other rows than the "
                                "matrix the pattern was read from");
  const int size = static_cast<int>(sent_.size());
  // declared rows of other ranks go to their owners
  if (size > 1)
  {
    std::vector<int> send_counts(size), recv_counts(size), send_at(size + 1, 0), recv_at(size + 1, 0);
    for (int r = 0; r < size; ++r)
      send_counts[r] = static_cast<int>(sent_[r].size());
    MPI_Alltoall(send_counts.data(), 1, MPI_INT, recv_counts.data(), 1, MPI_INT, comm);
    std::vector<PetscInt> send, recv;
    for (int r = 0; r < size; ++r)
    {
      send.insert(send.end(), sent_[r].begin(), sent_[r].end());
      send_at[r + 1] = send_at[r] + send_counts[r];
      recv_at[r + 1] = recv_at[r] + recv_counts[r];
      sent_[r].clear();
    }
    recv.resize(recv_at[size]);
    MPI_Alltoallv(send.data(), send_counts.data(), send_at.data(), MPIU_INT, recv.data(),
                  recv_counts.data(), recv_at.data(), MPIU_INT, comm);
    for (std::size_t p = 0; p < recv.size();)
    {
      const PetscInt row = recv[p], count = recv[p + 1];
      auto& target = added_.at(row - row_begin_);
      target.insert(target.end(), recv.begin() + p + 2, recv.begin() + p + 2 + count);
      p += 2 + count;
    }
  }
  // each row: base columns and declared ones, sorted, once each
  const PetscInt m = row_end_ - row_begin_;
  std::vector<PetscInt> start(m + 1, 0), cols;
  cols.reserve(base_cols_.size());
  for (PetscInt i = 0; i < m; ++i)
  {
    const std::size_t first = cols.size();
    cols.insert(cols.end(), base_cols_.begin() + base_start_[i], base_cols_.begin() + base_start_[i + 1]);
    cols.insert(cols.end(), added_[i].begin(), added_[i].end());
    added_[i].clear();
    std::sort(cols.begin() + first, cols.end());
    cols.erase(std::unique(cols.begin() + first, cols.end()), cols.end());
    start[i + 1] = static_cast<PetscInt>(cols.size());
  }
  const std::vector<PetscScalar> zeros(cols.size(), 0.0);

  MatType type;
  check(MatGetType(base, &type), "MatGetType");
  PetscInt n, M, N;
  PetscInt m_local;
  check(MatGetLocalSize(base, &m_local, &n), "MatGetLocalSize");
  check(MatGetSize(base, &M, &N), "MatGetSize");
  Mat A;
  check(MatCreate(comm, &A), "MatCreate");
  check(MatSetType(A, type), "MatSetType");
  check(MatSetSizes(A, m_local, n, M, N), "MatSetSizes");
  // each call is a no-op on the other type; both assemble A
  check(MatSeqAIJSetPreallocationCSR(A, start.data(), cols.data(), zeros.data()),
        "MatSeqAIJSetPreallocationCSR");
  check(MatMPIAIJSetPreallocationCSR(A, start.data(), cols.data(), zeros.data()),
        "MatMPIAIJSetPreallocationCSR");
  ISLocalToGlobalMapping rmap, cmap;
  check(MatGetLocalToGlobalMapping(base, &rmap, &cmap), "MatGetLocalToGlobalMapping");
  if (rmap and cmap)
    check(MatSetLocalToGlobalMapping(A, rmap, cmap), "MatSetLocalToGlobalMapping");
  // a coupling missed by the pattern costs a reallocation, not a failed run
  check(MatSetOption(A, MAT_NEW_NONZERO_LOCATION_ERR, PETSC_FALSE), "MatSetOption");
  check(MatSetOption(A, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_FALSE), "MatSetOption");
  return A;
}
} // namespace textile::assembly

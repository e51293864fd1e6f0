#include "node_block_matrix.h"
#include "../assembly/petsc_error.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>

namespace textile::contact
{
namespace
{
constexpr int dofs_per_node = 9;
constexpr int block_size = dofs_per_node * dofs_per_node;
} // namespace

void NodeBlockMatrix::build(std::span<const std::size_t> offsets,
                            std::span<const std::int64_t> nodes,
                            std::span<const std::int32_t> dofs)
{
  if (offsets.empty() or offsets.back() != nodes.size())
    throw std::invalid_argument("NodeBlockMatrix::build: offsets do not match nodes");
  dofs_.assign(dofs.begin(), dofs.end());
  const std::size_t ne = offsets.size() - 1;
  // a node takes part when one of its unknowns is free; its columns sort
  // by its first free global index (a node's 9 unknowns are consecutive)
  auto first_dof = [&](std::int64_t n)
  {
    if (n < 0 or static_cast<std::size_t>(dofs_per_node * (n + 1)) > dofs.size())
      throw std::invalid_argument("NodeBlockMatrix::build: node outside the dof array");
    for (int k = 0; k < dofs_per_node; ++k)
      if (dofs[dofs_per_node * n + k] >= 0)
        return static_cast<std::int64_t>(dofs[dofs_per_node * n + k]) - k;
    return std::int64_t{-1};
  };
  struct Pair
  {
    std::int64_t row, col_key, col;
    auto operator<=>(const Pair&) const = default;
  };
  std::vector<Pair> pairs;
  element_nodes_.resize(ne);
  for (std::size_t e = 0; e < ne; ++e)
  {
    element_nodes_[e] = static_cast<int>(offsets[e + 1] - offsets[e]);
    for (std::size_t a = offsets[e]; a < offsets[e + 1]; ++a)
    {
      if (first_dof(nodes[a]) < 0)
        continue;
      for (std::size_t b = offsets[e]; b < offsets[e + 1]; ++b)
        if (const std::int64_t key = first_dof(nodes[b]); key >= 0)
          pairs.push_back({nodes[a], key, nodes[b]});
    }
  }
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());

  row_node_.clear();
  row_start_.assign(1, 0);
  col_node_.resize(pairs.size());
  for (std::size_t p = 0; p < pairs.size(); ++p)
  {
    if (p == 0 or pairs[p].row != pairs[p - 1].row)
    {
      if (p > 0)
        row_start_.push_back(p);
      row_node_.push_back(pairs[p].row);
    }
    col_node_[p] = pairs[p].col;
  }
  if (!pairs.empty())
    row_start_.push_back(pairs.size());

  // each element's slots: block index of every (a, b) of its nodes
  element_start_.assign(ne + 1, 0);
  for (std::size_t e = 0; e < ne; ++e)
    element_start_[e + 1] = element_start_[e] + element_nodes_[e] * element_nodes_[e];
  element_block_.assign(element_start_.back(), -1);
  for (std::size_t e = 0; e < ne; ++e)
  {
    std::size_t slot = element_start_[e];
    for (std::size_t a = offsets[e]; a < offsets[e + 1]; ++a)
      for (std::size_t b = offsets[e]; b < offsets[e + 1]; ++b, ++slot)
      {
        const std::int64_t key = first_dof(nodes[b]);
        if (first_dof(nodes[a]) < 0 or key < 0)
          continue;
        const Pair wanted{nodes[a], key, nodes[b]};
        const auto it = std::lower_bound(pairs.begin(), pairs.end(), wanted);
        element_block_[slot] = static_cast<std::int32_t>(it - pairs.begin());
      }
  }
  slots_ = MatrixSlots();
  values_.resize(block_size * pairs.size()); // overwritten by a block's first contribution
  block_touched_.assign(pairs.size(), 0);
  touched_.clear();
  row_touched_.assign(row_node_.size(), 0);
  // the row of each block, to flag rows as blocks are touched
  block_row_.resize(pairs.size());
  for (std::size_t r = 0; r < row_node_.size(); ++r)
    std::fill(block_row_.begin() + row_start_[r], block_row_.begin() + row_start_[r + 1],
              static_cast<std::int32_t>(r));
}

bool NodeBlockMatrix::built_for(std::span<const std::int32_t> dofs) const
{
  return !element_start_.empty() and std::equal(dofs.begin(), dofs.end(), dofs_.begin(), dofs_.end());
}

void NodeBlockMatrix::add(std::size_t e, std::span<const double> K)
{
  const int n = element_nodes_.at(e);
  const std::size_t cols = static_cast<std::size_t>(dofs_per_node * n);
  if (K.size() != cols * cols)
    throw std::invalid_argument("NodeBlockMatrix::add: wrong tangent size");
  const std::int32_t* slot = element_block_.data() + element_start_[e];
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b, ++slot)
    {
      if (*slot < 0)
        continue;
      double* block = values_.data() + static_cast<std::size_t>(block_size) * *slot;
      const double* src = K.data() + dofs_per_node * (a * cols + b);
      if (block_touched_[*slot])
        for (int i = 0; i < dofs_per_node; ++i)
          for (int j = 0; j < dofs_per_node; ++j)
            block[dofs_per_node * i + j] += src[i * cols + j];
      else
      {
        // the first contribution since the last insertion overwrites: the
        // buffer is never cleared
        for (int i = 0; i < dofs_per_node; ++i)
          for (int j = 0; j < dofs_per_node; ++j)
            block[dofs_per_node * i + j] = src[i * cols + j];
        block_touched_[*slot] = 1;
        touched_.push_back(*slot);
      }
      row_touched_[block_row_[*slot]] = 1;
    }
}

void NodeBlockMatrix::insert_row(Mat A, std::size_t r, bool touched_only) const
{
  cols_.clear();
  for (std::size_t p = row_start_[r]; p < row_start_[r + 1]; ++p)
    if (!touched_only or block_touched_[p])
      for (int k = 0; k < dofs_per_node; ++k)
        cols_.push_back(dofs_[dofs_per_node * col_node_[p] + k]);
  const std::size_t ncols = cols_.size();
  // all blocks of the row (a pattern) are inserted as zeros
  row_values_.assign(dofs_per_node * ncols, 0.0);
  if (touched_only)
  {
    std::size_t c = 0;
    for (std::size_t p = row_start_[r]; p < row_start_[r + 1]; ++p)
    {
      if (!block_touched_[p])
        continue;
      const double* block = values_.data() + static_cast<std::size_t>(block_size) * p;
      for (int i = 0; i < dofs_per_node; ++i)
        std::copy_n(block + dofs_per_node * i, dofs_per_node,
                    row_values_.data() + i * ncols + c);
      c += dofs_per_node;
    }
  }
  const std::int32_t* rows = dofs_.data() + dofs_per_node * row_node_[r];
  // negative (constrained) rows and columns are skipped by PETSc
  // a pattern goes into a preallocator with INSERT_VALUES, as its base
  // pattern (PETSc refuses to mix the modes before an assembly)
  assembly::check(MatSetValues(A, dofs_per_node, rows, static_cast<PetscInt>(ncols), cols_.data(),
                               row_values_.data(), touched_only ? ADD_VALUES : INSERT_VALUES),
                  "MatSetValues");
}

void NodeBlockMatrix::locate(Mat A)
{
  using assembly::check;
  slots_ = MatrixSlots();
  slots_.matrix = A;
  check(MatGetNonzeroState(A, &slots_.nonzero_state), "MatGetNonzeroState");
  MatType type;
  check(MatGetType(A, &type), "MatGetType");
  const bool seq = std::strcmp(type, MATSEQAIJ) == 0, mpi = std::strcmp(type, MATMPIAIJ) == 0;
  if (!seq and !mpi)
    return; // MatSetValues for every row
  slots_.parallel = mpi;
  Mat diagonal = A, off_diagonal = nullptr;
  const PetscInt* garray = nullptr; // global column of each off-diagonal column
  if (mpi)
    check(MatMPIAIJGetSeqAIJ(A, &diagonal, &off_diagonal, &garray), "MatMPIAIJGetSeqAIJ");
  PetscInt r0, r1, c0, c1;
  check(MatGetOwnershipRange(A, &r0, &r1), "MatGetOwnershipRange");
  check(MatGetOwnershipRangeColumn(A, &c0, &c1), "MatGetOwnershipRangeColumn");
  struct Csr
  {
    PetscInt n = 0, columns = 0;
    const PetscInt *ia = nullptr, *ja = nullptr;
    PetscBool done = PETSC_FALSE;
  } d, o;
  check(MatGetRowIJ(diagonal, 0, PETSC_FALSE, PETSC_FALSE, &d.n, &d.ia, &d.ja, &d.done),
        "MatGetRowIJ");
  if (off_diagonal)
  {
    check(MatGetRowIJ(off_diagonal, 0, PETSC_FALSE, PETSC_FALSE, &o.n, &o.ia, &o.ja, &o.done),
          "MatGetRowIJ");
    PetscInt rows;
    check(MatGetSize(off_diagonal, &rows, &o.columns), "MatGetSize");
  }
  const bool have_csr = d.done and (!off_diagonal or o.done);
  if (have_csr)
  {
    slots_.direct = true;
    slots_.diagonal_size = static_cast<std::size_t>(d.ia[d.n]);
    slots_.position.assign(block_size * col_node_.size(), -1);
    slots_.block_direct.assign(col_node_.size(), 0);
    slots_.block_rows_contiguous.assign(col_node_.size(), 0);
    // slot of global (row, column), -2 when outside the pattern
    auto find = [](const Csr& m, PetscInt local_row, PetscInt column) -> std::int64_t
    {
      const PetscInt* first = m.ja + m.ia[local_row];
      const PetscInt* last = m.ja + m.ia[local_row + 1];
      const PetscInt* it = std::lower_bound(first, last, column);
      return (it != last and *it == column) ? static_cast<std::int64_t>(it - m.ja) : -2;
    };
    auto slot_of = [&](std::int32_t row, std::int32_t col) -> std::int64_t
    {
      if (col >= c0 and col < c1)
        return find(d, row - r0, col - c0);
      if (!off_diagonal)
        return -2;
      const PetscInt* g = std::lower_bound(garray, garray + o.columns, col);
      if (g == garray + o.columns or *g != col)
        return -2;
      const std::int64_t slot = find(o, row - r0, static_cast<PetscInt>(g - garray));
      return slot < 0 ? slot : slot + static_cast<std::int64_t>(slots_.diagonal_size);
    };
    // global column of a slot of a row, -1 outside the row (the inverse of
    // slot_of)
    auto column_at = [&](std::int32_t row, std::int64_t slot) -> std::int64_t
    {
      const PetscInt lr = row - r0;
      const std::int64_t nd = static_cast<std::int64_t>(slots_.diagonal_size);
      if (slot < nd)
        return slot >= d.ia[lr] and slot < d.ia[lr + 1] ? d.ja[slot] + c0 : -1;
      const std::int64_t k = slot - nd;
      return off_diagonal and k >= o.ia[lr] and k < o.ia[lr + 1] ? garray[o.ja[k]] : -1;
    };
    for (std::size_t r = 0; r < row_node_.size(); ++r)
    {
      // a block is summed in place when all its rows are owned here and all
      // its entries are in the pattern (constrained ones are skipped)
      bool owned = true;
      for (int i = 0; i < dofs_per_node; ++i)
      {
        const std::int32_t row = dofs_[dofs_per_node * row_node_[r] + i];
        owned = owned and (row < 0 or (row >= r0 and row < r1));
      }
      if (!owned)
        continue; // stashed by MatSetValues for its owner
      for (std::size_t p = row_start_[r]; p < row_start_[r + 1]; ++p)
      {
        bool inside = true;
        for (int i = 0; i < dofs_per_node and inside; ++i)
        {
          const std::int32_t row = dofs_[dofs_per_node * row_node_[r] + i];
          for (int j = 0; j < dofs_per_node and inside and row >= 0; ++j)
          {
            const std::int32_t col = dofs_[dofs_per_node * col_node_[p] + j];
            if (col < 0)
              continue;
            // a node's columns are consecutive in the pattern: the slot
            // after the previous column's, when it holds this column
            const std::int64_t* previous
                = j > 0 ? &slots_.position[block_size * p + dofs_per_node * i + j - 1] : nullptr;
            const std::int64_t slot = previous and *previous >= 0
                                              and column_at(row, *previous + 1) == col
                                          ? *previous + 1
                                          : slot_of(row, col);
            inside = slot >= 0;
            slots_.position[block_size * p + dofs_per_node * i + j] = slot;
          }
        }
        slots_.block_direct[p] = inside;
        // contiguous when every row of the block has its 9 slots side by
        // side (all columns free, consecutive in the pattern, one part)
        bool contiguous = inside;
        for (int i = 0; i < dofs_per_node and contiguous; ++i)
        {
          const std::int64_t* at = &slots_.position[block_size * p + dofs_per_node * i];
          for (int j = 0; j < dofs_per_node and contiguous; ++j)
            contiguous = at[0] >= 0 and at[j] == at[0] + j
                         and (at[0] < static_cast<std::int64_t>(slots_.diagonal_size))
                                 == (at[j] < static_cast<std::int64_t>(slots_.diagonal_size));
        }
        slots_.block_rows_contiguous[p] = contiguous;
      }
    }
  }
  check(MatRestoreRowIJ(diagonal, 0, PETSC_FALSE, PETSC_FALSE, &d.n, &d.ia, &d.ja, &d.done),
        "MatRestoreRowIJ");
  if (off_diagonal)
    check(MatRestoreRowIJ(off_diagonal, 0, PETSC_FALSE, PETSC_FALSE, &o.n, &o.ia, &o.ja,
                          &o.done),
          "MatRestoreRowIJ");
}

void NodeBlockMatrix::insert(Mat A)
{
  using assembly::check;
  PetscObjectState state;
  check(MatGetNonzeroState(A, &state), "MatGetNonzeroState");
  if (slots_.matrix != A or slots_.nonzero_state != state)
    locate(A);
  if (slots_.direct)
  {
    // each block summed once into its slots (an element-by-element sum
    // into the matrix would touch its scattered slots several times more)
    Mat diagonal = A, off_diagonal = nullptr;
    if (slots_.parallel)
      check(MatMPIAIJGetSeqAIJ(A, &diagonal, &off_diagonal, nullptr), "MatMPIAIJGetSeqAIJ");
    PetscScalar *ad = nullptr, *ao = nullptr;
    check(MatSeqAIJGetArray(diagonal, &ad), "MatSeqAIJGetArray");
    if (off_diagonal)
      check(MatSeqAIJGetArray(off_diagonal, &ao), "MatSeqAIJGetArray");
    const std::int64_t nd = static_cast<std::int64_t>(slots_.diagonal_size);
    // in block order, which is the matrix's row order: its arrays are then
    // walked forward instead of at random
    std::sort(touched_.begin(), touched_.end());
    for (const std::int32_t p : touched_)
    {
      if (!slots_.block_direct[p])
        continue;
      double* v = values_.data() + static_cast<std::size_t>(block_size) * p;
      const std::int64_t* slot = slots_.position.data() + static_cast<std::size_t>(block_size) * p;
      if (slots_.block_rows_contiguous[p])
      {
        // a node's 9 columns sit side by side in each row of the block
        for (int i = 0; i < dofs_per_node; ++i)
        {
          const std::int64_t at = slot[dofs_per_node * i];
          double* dst = at < nd ? ad + at : ao + (at - nd);
          for (int j = 0; j < dofs_per_node; ++j)
            dst[j] += v[dofs_per_node * i + j];
        }
      }
      else
        for (int k = 0; k < block_size; ++k)
        {
          if (slot[k] < 0)
            continue;
          if (slot[k] < nd)
            ad[slot[k]] += v[k];
          else
            ao[slot[k] - nd] += v[k];
        }
      block_touched_[p] = 0;
    }
    check(MatSeqAIJRestoreArray(diagonal, &ad), "MatSeqAIJRestoreArray");
    if (off_diagonal)
      check(MatSeqAIJRestoreArray(off_diagonal, &ao), "MatSeqAIJRestoreArray");
  }
  // the rest (other ranks' rows, new entries, other types): MatSetValues
  // after the arrays are given back, as it may reallocate them
  for (const std::int32_t p : touched_)
  {
    const std::int32_t r = block_row_[p];
    if (!block_touched_[p] or !row_touched_[r])
      continue;
    insert_row(A, r, true);
    for (std::size_t b = row_start_[r]; b < row_start_[r + 1]; ++b)
      block_touched_[b] = 0;
    row_touched_[r] = 0;
  }
  for (const std::int32_t p : touched_)
    row_touched_[block_row_[p]] = 0;
  touched_.clear();
}

void NodeBlockMatrix::insert_pattern(Mat P) const
{
  for (std::size_t r = 0; r < row_node_.size(); ++r)
    insert_row(P, r, false);
}
} // namespace textile::contact

#include "node_block_matrix.h"
#include "../node_unknowns.h"
#include "../assembly/aij_arrays.h"
#include "../assembly/petsc_error.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>

namespace textile::contact
{
namespace
{
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

void NodeBlockMatrix::insert_row(Mat A, std::size_t r) const
{
  cols_.clear();
  for (std::size_t p = row_start_[r]; p < row_start_[r + 1]; ++p)
    if (block_touched_[p])
      for (int k = 0; k < dofs_per_node; ++k)
        cols_.push_back(dofs_[dofs_per_node * col_node_[p] + k]);
  const std::size_t ncols = cols_.size();
  row_values_.resize(dofs_per_node * ncols);
  std::size_t c = 0;
  for (std::size_t p = row_start_[r]; p < row_start_[r + 1]; ++p)
  {
    if (!block_touched_[p])
      continue;
    const double* block = values_.data() + static_cast<std::size_t>(block_size) * p;
    for (int i = 0; i < dofs_per_node; ++i)
      std::copy_n(block + dofs_per_node * i, dofs_per_node, row_values_.data() + i * ncols + c);
    c += dofs_per_node;
  }
  const std::int32_t* rows = dofs_.data() + dofs_per_node * row_node_[r];
  // negative (constrained) rows and columns are skipped by PETSc
  assembly::check(MatSetValues(A, dofs_per_node, rows, static_cast<PetscInt>(ncols), cols_.data(),
                               row_values_.data(), ADD_VALUES),
                  "MatSetValues");
}

void NodeBlockMatrix::locate(Mat A)
{
  using assembly::check;
  slots_ = MatrixSlots();
  slots_.matrix = A;
  check(MatGetNonzeroState(A, &slots_.nonzero_state), "MatGetNonzeroState");
  slots_.parallel = assembly::has_type(A, MATMPIAIJ);
  PetscInt r0 = 0, r1 = 0;
  check(MatGetOwnershipRange(A, &r0, &r1), "MatGetOwnershipRange");
  // a block row is owned here when all its free rows are
  slots_.row_owned.assign(row_node_.size(), 1);
  for (std::size_t r = 0; r < row_node_.size(); ++r)
    for (int i = 0; i < dofs_per_node; ++i)
    {
      const std::int32_t row = dofs_[dofs_per_node * row_node_[r] + i];
      if (row >= 0 and (row < r0 or row >= r1))
        slots_.row_owned[r] = 0;
    }
  if (slots_.parallel)
    for (std::size_t r = 0; r < row_node_.size(); ++r)
      if (!slots_.row_owned[r])
        for (std::size_t p = row_start_[r]; p < row_start_[r + 1]; ++p)
          slots_.off_rank.push_back(static_cast<std::int32_t>(p));

  const assembly::AijPattern pattern(A);
  if (!pattern.usable())
    return; // MatSetValues for every owned row
  slots_.direct = true;
  slots_.diagonal_size = static_cast<std::size_t>(pattern.diagonal_size());
  slots_.position.assign(block_size * col_node_.size(), -1);
  slots_.block_direct.assign(col_node_.size(), 0);
  slots_.block_rows_contiguous.assign(col_node_.size(), 0);
  for (std::size_t r = 0; r < row_node_.size(); ++r)
  {
    // a block is summed in place when its rows are owned here and all its
    // entries are in the pattern (constrained ones are skipped)
    if (!slots_.row_owned[r])
      continue;
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
                                            and pattern.column(row, *previous + 1) == col
                                        ? *previous + 1
                                        : pattern.slot(row, col);
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

void NodeBlockMatrix::setup_off_rank(Mat A)
{
  std::vector<std::int32_t> rows, cols;
  rows.reserve(dofs_per_node * slots_.off_rank.size());
  cols.reserve(dofs_per_node * slots_.off_rank.size());
  for (const std::int32_t p : slots_.off_rank)
  {
    const std::int32_t* r = dofs_.data() + dofs_per_node * row_node_[block_row_[p]];
    const std::int32_t* c = dofs_.data() + dofs_per_node * col_node_[p];
    rows.insert(rows.end(), r, r + dofs_per_node);
    cols.insert(cols.end(), c, c + dofs_per_node);
  }
  off_rank_.setup(A, dofs_per_node, rows, cols);
}

void NodeBlockMatrix::insert(Mat A)
{
  using assembly::check;
  PetscObjectState state;
  check(MatGetNonzeroState(A, &state), "MatGetNonzeroState");
  const bool stale = slots_.matrix != A or slots_.nonzero_state != state;
  // on an mpiaij matrix of several ranks the blocks of other ranks' rows
  // go to their owners: every rank takes part, and all locate again when
  // one has a new layout or pattern
  MPI_Comm comm;
  check(PetscObjectGetComm(reinterpret_cast<PetscObject>(A), &comm), "PetscObjectGetComm");
  int comm_size = 1;
  MPI_Comm_size(comm, &comm_size);
  const bool exchange = comm_size > 1 and assembly::has_type(A, MATMPIAIJ);
  if (stale)
    locate(A);
  if (exchange)
  {
    int any_stale = stale;
    MPI_Allreduce(MPI_IN_PLACE, &any_stale, 1, MPI_INT, MPI_LOR, comm);
    if (any_stale)
      setup_off_rank(A);
  }
  if (slots_.direct)
  {
    // each block summed once into its slots (an element-by-element sum
    // into the matrix would touch its scattered slots several times more)
    assembly::AijValues a(A, static_cast<std::int64_t>(slots_.diagonal_size));
    double* ad = a.diagonal();
    double* ao = a.off_diagonal();
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
          if (slot[k] >= 0)
            a[slot[k]] += v[k];
      block_touched_[p] = 0;
    }
  }
  if (exchange)
  {
    const std::span<const std::int32_t> off_rank(slots_.off_rank);
    for (const std::int32_t p : off_rank)
      off_rank_counts_.sent += block_touched_[p];
    off_rank_.add(A, off_rank, block_touched_, values_);
    for (const std::int32_t p : off_rank)
      block_touched_[p] = 0;
  }
  // the rest (new entries, other types, other ranks' rows without the
  // exchange): MatSetValues after the arrays are given back, as it may
  // reallocate them
  for (const std::int32_t p : touched_)
  {
    const std::int32_t r = block_row_[p];
    if (!block_touched_[p] or !row_touched_[r])
      continue;
    if (!slots_.row_owned.empty() and !slots_.row_owned[r])
      for (std::size_t b = row_start_[r]; b < row_start_[r + 1]; ++b)
        off_rank_counts_.stashed += block_touched_[b];
    insert_row(A, r);
    for (std::size_t b = row_start_[r]; b < row_start_[r + 1]; ++b)
      block_touched_[b] = 0;
    row_touched_[r] = 0;
  }
  for (const std::int32_t p : touched_)
    row_touched_[block_row_[p]] = 0;
  touched_.clear();
}

void NodeBlockMatrix::insert_pattern(assembly::SparsityPattern& pattern) const
{
  for (std::size_t r = 0; r < row_node_.size(); ++r)
  {
    cols_.clear();
    for (std::size_t p = row_start_[r]; p < row_start_[r + 1]; ++p)
      for (int k = 0; k < dofs_per_node; ++k)
        cols_.push_back(dofs_[dofs_per_node * col_node_[p] + k]);
    pattern.add({dofs_.data() + dofs_per_node * row_node_[r], dofs_per_node}, cols_);
  }
}
} // namespace textile::contact

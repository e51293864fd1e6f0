#include "petsc_insert.h"
#include "aij_arrays.h"
#include "ordered_pipeline.h"
#include "petsc_error.h"

#include <algorithm>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>

namespace textile::assembly
{
void add_block(Mat A, std::span<const std::int32_t> rows, std::span<const std::int32_t> cols,
               std::span<const double> values)
{
  static_assert(std::is_same_v<PetscInt, std::int32_t>, "PETSc must use 32-bit indices here");
  static_assert(std::is_same_v<PetscScalar, double>, "PETSc must use real double scalars");
  if (values.size() != rows.size() * cols.size())
    throw std::invalid_argument("add_block: values size does not match rows x cols");
  check(MatSetValuesLocal(A, static_cast<PetscInt>(rows.size()), rows.data(),
                          static_cast<PetscInt>(cols.size()), cols.data(), values.data(),
                          ADD_VALUES),
        "MatSetValuesLocal");
}

void add_entries(Mat A, std::span<const std::int32_t> rows, std::span<const std::int32_t> cols,
                 std::span<const double> values)
{
  if (rows.size() != cols.size() or rows.size() != values.size())
    throw std::invalid_argument("add_entries: rows, cols and values differ in length");
  for (std::size_t k = 0; k < rows.size(); ++k)
  {
    if (rows[k] < 0 or cols[k] < 0)
      continue;
    check(MatSetValuesLocal(A, 1, &rows[k], 1, &cols[k], &values[k], ADD_VALUES),
          "MatSetValuesLocal");
  }
}

void add_diagonal(Mat A, std::span<const std::int32_t> rows, double value)
{
  for (std::int32_t i : rows)
  {
    if (i < 0)
      continue;
    check(MatSetValuesLocal(A, 1, &i, 1, &i, &value, ADD_VALUES), "MatSetValuesLocal");
  }
}

bool BlockInsertion::matches(Mat A, std::span<const std::int32_t> indices, int block_size) const
{
  PetscObjectId id;
  check(PetscObjectGetId(reinterpret_cast<PetscObject>(A), &id), "PetscObjectGetId");
  PetscObjectState state;
  check(MatGetNonzeroState(A, &state), "MatGetNonzeroState");
  return id == _id and state == _nonzero_state and block_size == _block_size
         and std::equal(indices.begin(), indices.end(), _indices.begin(), _indices.end());
}

void BlockInsertion::find_positions(Mat A, std::span<const std::int32_t> indices,
                                    int block_size)
{
  check(PetscObjectGetId(reinterpret_cast<PetscObject>(A), &_id), "PetscObjectGetId");
  check(MatGetNonzeroState(A, &_nonzero_state), "MatGetNonzeroState");
  _block_size = block_size;
  _indices.assign(indices.begin(), indices.end());
  _position.clear();
  _remote_blocks.clear();
  _remote_rows.clear();
  _direct = false;
  PetscBool assembled = PETSC_FALSE;
  check(MatAssembled(A, &assembled), "MatAssembled");
  if (!assembled)
    return; // no final pattern yet: add_block
  const AijPattern pattern(A);
  if (!pattern.usable())
    return; // not AIJ: add_block
  _diagonal_size = pattern.diagonal_size();

  // global numbers of the local indices (negative stay negative)
  ISLocalToGlobalMapping rmap, cmap;
  check(MatGetLocalToGlobalMapping(A, &rmap, &cmap), "MatGetLocalToGlobalMapping");
  std::vector<PetscInt> rows(indices.size()), cols(indices.size());
  check(ISLocalToGlobalMappingApply(rmap, indices.size(), indices.data(), rows.data()),
        "ISLocalToGlobalMappingApply");
  check(ISLocalToGlobalMappingApply(cmap, indices.size(), indices.data(), cols.data()),
        "ISLocalToGlobalMappingApply");
  const PetscInt rstart = pattern.row_begin(), rend = pattern.row_end();

  const std::size_t bs = block_size, nb = indices.size() / bs;
  _position.assign(nb * bs * bs, -1);
  for (std::size_t b = 0; b < nb; ++b)
  {
    bool remote = false;
    for (std::size_t i = 0; i < bs; ++i)
    {
      const PetscInt row = rows[b * bs + i];
      if (indices[b * bs + i] < 0)
        continue;
      if (row < rstart or row >= rend)
      {
        remote = true;
        continue;
      }
      for (std::size_t j = 0; j < bs; ++j)
      {
        if (indices[b * bs + j] < 0)
          continue;
        const std::int64_t slot = pattern.slot(row, cols[b * bs + j]);
        if (slot < 0)
          return; // outside the pattern: add_block (and its PETSc error)
        _position[(b * bs + i) * bs + j] = slot;
      }
    }
    if (remote)
    {
      _remote_blocks.push_back(b);
      for (std::size_t i = 0; i < bs; ++i)
      {
        const PetscInt row = rows[b * bs + i];
        const bool mine = row >= rstart and row < rend;
        _remote_rows.push_back(mine ? -1 : indices[b * bs + i]);
      }
    }
  }
  _direct = true;
}

void BlockInsertion::add_blocks(Mat A, std::span<const std::int32_t> indices, int block_size,
                                const std::function<void(std::size_t, std::span<double>)>& fill,
                                int num_threads)
{
  if (block_size <= 0 or indices.size() % block_size != 0)
    throw std::invalid_argument("BlockInsertion: indices must hold whole blocks");
  if (!matches(A, indices, block_size))
    find_positions(A, indices, block_size);
  const std::size_t bs = block_size, nb = indices.size() / bs;

  std::unique_ptr<AijValues> matrix_values
      = _direct ? std::make_unique<AijValues>(A, _diagonal_size) : nullptr;
  std::size_t next_remote = 0;
  auto add = [&](std::size_t b, std::span<const double> values)
  {
    const auto idx = indices.subspan(b * bs, bs);
    if (!_direct)
    {
      add_block(A, idx, idx, values);
      return;
    }
    const std::int64_t* pos = _position.data() + b * bs * bs;
    AijValues& a = *matrix_values;
    for (std::size_t k = 0; k < bs * bs; ++k)
      if (pos[k] >= 0)
        a[pos[k]] += values[k];
    if (next_remote < _remote_blocks.size() and _remote_blocks[next_remote] == b)
    {
      // rows of another rank: PETSc's stash (skips the rows marked -1)
      add_block(A, std::span(_remote_rows).subspan(next_remote * bs, bs), idx, values);
      ++next_remote;
    }
  };

  // chunks of blocks computed on the threads, added in order by this one
  // while the others compute the next chunks
  const std::size_t chunk = num_threads > 1 ? 16 : 1;
  const std::size_t num_chunks = (nb + chunk - 1) / chunk;
  const std::size_t slots = num_threads > 1 ? 4 * num_threads : 1;
  std::vector<double> values(slots * chunk * bs * bs);
  auto slot_values = [&](std::size_t slot, std::size_t i)
  { return std::span(values).subspan((slot * chunk + i) * bs * bs, bs * bs); };
  ordered_pipeline(
      num_chunks, num_threads, slots,
      [&](std::size_t c, std::size_t slot)
      {
        for (std::size_t b = c * chunk; b < std::min(nb, (c + 1) * chunk); ++b)
        {
          const auto v = slot_values(slot, b - c * chunk);
          std::memset(v.data(), 0, v.size_bytes());
          fill(b, v);
        }
      },
      [&](std::size_t c, std::size_t slot)
      {
        for (std::size_t b = c * chunk; b < std::min(nb, (c + 1) * chunk); ++b)
          add(b, slot_values(slot, b - c * chunk));
      });
}

} // namespace textile::assembly

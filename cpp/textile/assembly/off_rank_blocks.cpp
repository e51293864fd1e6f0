#include "off_rank_blocks.h"
#include "aij_arrays.h"
#include "petsc_error.h"

#include <algorithm>
#include <numeric>
#include <stdexcept>
#include <string>

namespace textile::assembly
{
namespace
{
MPI_Comm communicator(Mat A)
{
  MPI_Comm comm;
  check(PetscObjectGetComm(reinterpret_cast<PetscObject>(A), &comm), "PetscObjectGetComm");
  return comm;
}

std::vector<int> displacements(const std::vector<int>& counts)
{
  std::vector<int> d(counts.size(), 0);
  for (std::size_t i = 1; i < counts.size(); ++i)
    d[i] = d[i - 1] + counts[i - 1];
  return d;
}

std::vector<int> scaled(const std::vector<int>& counts, int factor)
{
  std::vector<int> out(counts);
  for (int& c : out)
    c *= factor;
  return out;
}

void mpi_check(int err, const char* what)
{
  if (err != MPI_SUCCESS)
    throw std::runtime_error(std::string(what) + " failed");
}
} // namespace

void OffRankBlocks::setup(Mat A, int bs, std::span<const std::int32_t> rows,
                          std::span<const std::int32_t> cols)
{
  if (bs <= 0 or rows.size() % bs != 0 or cols.size() != rows.size())
    throw std::invalid_argument("OffRankBlocks::setup: rows and cols must hold whole blocks");
  const MPI_Comm comm = communicator(A);
  int size, rank;
  MPI_Comm_size(comm, &size);
  MPI_Comm_rank(comm, &rank);
  const PetscInt* ranges;
  check(MatGetOwnershipRanges(A, &ranges), "MatGetOwnershipRanges");
  _bs = bs;
  _num_blocks = rows.size() / bs;

  // destination of each block: the owner of its rows
  std::vector<int> dest(_num_blocks, -1);
  for (std::size_t b = 0; b < _num_blocks; ++b)
  {
    for (int i = 0; i < bs; ++i)
    {
      const std::int32_t row = rows[b * bs + i];
      if (row < 0)
        continue;
      const int owner = static_cast<int>(std::upper_bound(ranges, ranges + size + 1, row) - ranges) - 1;
      if (owner == rank or owner < 0 or owner >= size or (dest[b] >= 0 and dest[b] != owner))
        throw std::invalid_argument(
            "OffRankBlocks::setup: a block's rows must all belong to one other rank");
      dest[b] = owner;
    }
  }
  _order.clear();
  _send_blocks.assign(size, 0);
  for (int d = 0; d < size; ++d)
    for (std::size_t b = 0; b < _num_blocks; ++b)
      if (dest[b] == d)
      {
        _order.push_back(static_cast<std::int32_t>(b));
        ++_send_blocks[d];
      }
  _recv_blocks.assign(size, 0);
  mpi_check(MPI_Alltoall(_send_blocks.data(), 1, MPI_INT, _recv_blocks.data(), 1, MPI_INT, comm),
            "MPI_Alltoall");

  // the blocks' rows and columns, to their owners
  const int per_block = 2 * bs;
  std::vector<std::int32_t> out;
  out.reserve(_order.size() * per_block);
  for (const std::int32_t b : _order)
  {
    out.insert(out.end(), rows.begin() + b * bs, rows.begin() + (b + 1) * bs);
    out.insert(out.end(), cols.begin() + b * bs, cols.begin() + (b + 1) * bs);
  }
  const std::vector<int> send_counts = scaled(_send_blocks, per_block);
  const std::vector<int> recv_counts = scaled(_recv_blocks, per_block);
  const std::size_t num_in = std::accumulate(_recv_blocks.begin(), _recv_blocks.end(), std::size_t{0});
  std::vector<std::int32_t> in(num_in * per_block);
  mpi_check(MPI_Alltoallv(out.data(), send_counts.data(), displacements(send_counts).data(),
                          MPI_INT32_T, in.data(), recv_counts.data(),
                          displacements(recv_counts).data(), MPI_INT32_T, comm),
            "MPI_Alltoallv");

  // where each received entry goes
  const AijPattern pattern(A);
  _diagonal_size = pattern.diagonal_size();
  _slots.assign(num_in * bs * bs, -1);
  _outside.assign(num_in, pattern.usable() ? 0 : 1);
  _recv_rows.resize(num_in * bs);
  _recv_cols.resize(num_in * bs);
  for (std::size_t k = 0; k < num_in; ++k)
  {
    const std::int32_t* r = in.data() + k * per_block;
    const std::int32_t* c = r + bs;
    std::copy_n(r, bs, _recv_rows.begin() + k * bs);
    std::copy_n(c, bs, _recv_cols.begin() + k * bs);
    if (_outside[k])
      continue;
    for (int i = 0; i < bs and !_outside[k]; ++i)
    {
      if (r[i] < 0)
        continue;
      if (r[i] < pattern.row_begin() or r[i] >= pattern.row_end())
        throw std::runtime_error("OffRankBlocks::setup: received a row owned elsewhere");
      for (int j = 0; j < bs; ++j)
      {
        if (c[j] < 0)
          continue;
        const std::int64_t slot = pattern.slot(r[i], c[j]);
        if (slot < 0)
        {
          _outside[k] = 1;
          break;
        }
        _slots[(k * bs + i) * bs + j] = slot;
      }
    }
  }
}

std::size_t OffRankBlocks::add(Mat A, std::span<const std::int32_t> where,
                               std::span<const char> touched, std::span<const double> values)
{
  const std::size_t bb = static_cast<std::size_t>(_bs) * _bs;
  if (where.size() != _num_blocks)
    throw std::invalid_argument("OffRankBlocks::add: one place a block");
  const MPI_Comm comm = communicator(A);
  // flags, then the values of flagged blocks, in destination order
  _flags_out.resize(_order.size());
  _values_out.clear();
  const int size = static_cast<int>(_send_blocks.size());
  std::vector<int> send_values(size, 0);
  for (int d = 0, k = 0; d < size; ++d)
    for (int n = 0; n < _send_blocks[d]; ++n, ++k)
    {
      const std::size_t w = where[_order[k]];
      _flags_out[k] = touched[w];
      if (touched[w])
      {
        _values_out.insert(_values_out.end(), values.begin() + w * bb,
                           values.begin() + (w + 1) * bb);
        send_values[d] += static_cast<int>(bb);
      }
    }
  const std::size_t num_in = _outside.size();
  _flags_in.resize(num_in);
  mpi_check(MPI_Alltoallv(_flags_out.data(), _send_blocks.data(),
                          displacements(_send_blocks).data(), MPI_CHAR, _flags_in.data(),
                          _recv_blocks.data(), displacements(_recv_blocks).data(), MPI_CHAR,
                          comm),
            "MPI_Alltoallv");
  std::vector<int> recv_values(size, 0);
  std::size_t received = 0;
  for (int s = 0, k = 0; s < size; ++s)
    for (int n = 0; n < _recv_blocks[s]; ++n, ++k)
      if (_flags_in[k])
      {
        recv_values[s] += static_cast<int>(bb);
        ++received;
      }
  _values_in.resize(received * bb);
  mpi_check(MPI_Alltoallv(_values_out.data(), send_values.data(),
                          displacements(send_values).data(), MPI_DOUBLE, _values_in.data(),
                          recv_values.data(), displacements(recv_values).data(), MPI_DOUBLE,
                          comm),
            "MPI_Alltoallv");

  // add: in place first, then what lies outside the pattern (MatSetValues
  // may reallocate the arrays)
  bool any_inside = false, any_outside = false;
  for (std::size_t k = 0; k < num_in; ++k)
    if (_flags_in[k])
      (_outside[k] ? any_outside : any_inside) = true;
  if (any_inside)
  {
    AijValues a(A, _diagonal_size);
    const double* v = _values_in.data();
    for (std::size_t k = 0; k < num_in; ++k)
    {
      if (!_flags_in[k])
        continue;
      if (!_outside[k])
      {
        const std::int64_t* slot = _slots.data() + k * bb;
        for (std::size_t e = 0; e < bb; ++e)
          if (slot[e] >= 0)
            a[slot[e]] += v[e];
      }
      v += bb;
    }
  }
  if (any_outside)
  {
    const double* v = _values_in.data();
    for (std::size_t k = 0; k < num_in; ++k)
    {
      if (!_flags_in[k])
        continue;
      if (_outside[k])
        check(MatSetValues(A, _bs, _recv_rows.data() + k * _bs, _bs,
                           _recv_cols.data() + k * _bs, v, ADD_VALUES),
              "MatSetValues");
      v += bb;
    }
  }
  return received;
}
} // namespace textile::assembly

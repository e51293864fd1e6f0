#include "aij_arrays.h"

namespace textile::assembly
{
AijPattern::AijPattern(Mat A)
{
  const bool mpi = has_type(A, MATMPIAIJ);
  if (!mpi and !has_type(A, MATSEQAIJ))
    return;
  PetscBool assembled = PETSC_FALSE;
  check(MatAssembled(A, &assembled), "MatAssembled");
  check(MatGetOwnershipRange(A, &_r0, &_r1), "MatGetOwnershipRange");
  check(MatGetOwnershipRangeColumn(A, &_c0, &_c1), "MatGetOwnershipRangeColumn");
  Mat diagonal = A, off_diagonal = nullptr;
  if (mpi)
  {
    check(MatMPIAIJGetSeqAIJ(A, &diagonal, &off_diagonal, &_garray), "MatMPIAIJGetSeqAIJ");
    // before its first assembly an mpiaij's off-diagonal part is numbered
    // by global column, without the compressed column map
    if (!_garray and !assembled)
      return;
  }
  _diagonal = std::make_unique<RowIJ>(diagonal);
  _diagonal_size = _diagonal->csr.ia[_diagonal->csr.n];
  if (off_diagonal)
  {
    _off_diagonal = std::make_unique<RowIJ>(off_diagonal);
    PetscInt rows;
    check(MatGetSize(off_diagonal, &rows, &_num_off), "MatGetSize");
  }
  _usable = true;
}

std::int64_t AijPattern::slot(PetscInt row, PetscInt col) const
{
  if (col >= _c0 and col < _c1)
  {
    const std::int32_t at = _diagonal->csr.find(row - _r0, col - _c0);
    return at < 0 ? -2 : at;
  }
  if (!_off_diagonal or !_garray)
    return -2;
  const PetscInt* g = std::lower_bound(_garray, _garray + _num_off, col);
  if (g == _garray + _num_off or *g != col)
    return -2;
  const std::int32_t at
      = _off_diagonal->csr.find(row - _r0, static_cast<PetscInt>(g - _garray));
  return at < 0 ? -2 : at + _diagonal_size;
}

std::int64_t AijPattern::column(PetscInt row, std::int64_t slot) const
{
  const PetscInt lr = row - _r0;
  const Csr& d = _diagonal->csr;
  if (slot < _diagonal_size)
    return slot >= d.ia[lr] and slot < d.ia[lr + 1] ? d.ja[slot] + _c0 : -1;
  if (!_off_diagonal)
    return -1;
  const Csr& o = _off_diagonal->csr;
  const std::int64_t k = slot - _diagonal_size;
  return k >= o.ia[lr] and k < o.ia[lr + 1] ? _garray[o.ja[k]] : -1;
}

AijValues::AijValues(Mat A, std::int64_t diagonal_size) : _diagonal_size(diagonal_size)
{
  if (has_type(A, MATMPIAIJ))
  {
    Mat diagonal, off_diagonal;
    check(MatMPIAIJGetSeqAIJ(A, &diagonal, &off_diagonal, nullptr), "MatMPIAIJGetSeqAIJ");
    _diagonal = std::make_unique<Values>(diagonal);
    _off = std::make_unique<Values>(off_diagonal);
  }
  else
    _diagonal = std::make_unique<Values>(A);
}
} // namespace textile::assembly

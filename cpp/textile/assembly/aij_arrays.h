// Direct access to an assembled AIJ matrix's arrays: where a (row, column)
// entry lives in its value arrays, and the value arrays themselves.
//
// MatSetValues searches every value's column in its row (a binary search a
// value, ~20 ns): for element blocks added every Newton iteration that
// costs more than the kernels computing them. The assemblers therefore
// locate each entry once per matrix pattern and add into the arrays.
#pragma once

#include "petsc_error.h"

#include <petscmat.h>

#include <algorithm>
#include <cstdint>
#include <memory>
#include <stdexcept>

namespace textile::assembly
{

/// CSR structure of a sequential AIJ matrix (row starts, column indices).
struct Csr
{
  PetscInt n = 0;
  const PetscInt* ia = nullptr;
  const PetscInt* ja = nullptr;

  /// Position of column col in row row, or -1.
  std::int32_t find(PetscInt row, PetscInt col) const
  {
    const PetscInt* begin = ja + ia[row];
    const PetscInt* end = ja + ia[row + 1];
    const PetscInt* it = std::lower_bound(begin, end, col);
    return (it != end and *it == col) ? static_cast<std::int32_t>(it - ja) : -1;
  }
};

/// Borrowed CSR arrays of a sequential AIJ matrix, handed back on destruction.
class RowIJ
{
public:
  explicit RowIJ(Mat A) : _A(A)
  {
    PetscBool done = PETSC_FALSE;
    check(MatGetRowIJ(A, 0, PETSC_FALSE, PETSC_FALSE, &csr.n, &csr.ia, &csr.ja, &done),
          "MatGetRowIJ");
    if (!done)
      throw std::runtime_error("MatGetRowIJ: no CSR structure");
  }
  ~RowIJ()
  {
    PetscBool done;
    MatRestoreRowIJ(_A, 0, PETSC_FALSE, PETSC_FALSE, &csr.n, &csr.ia, &csr.ja, &done);
  }
  RowIJ(const RowIJ&) = delete;
  RowIJ& operator=(const RowIJ&) = delete;
  Csr csr;

private:
  Mat _A;
};

/// Borrowed value array of a sequential AIJ matrix, handed back on destruction.
class Values
{
public:
  explicit Values(Mat A) : _A(A) { check(MatSeqAIJGetArray(A, &data), "MatSeqAIJGetArray"); }
  ~Values() { MatSeqAIJRestoreArray(_A, &data); }
  Values(const Values&) = delete;
  Values& operator=(const Values&) = delete;
  PetscScalar* data = nullptr;

private:
  Mat _A;
};

/// Whether A is of PETSc type `type`.
inline bool has_type(Mat A, const char* type)
{
  PetscBool same = PETSC_FALSE;
  check(PetscObjectTypeCompare(reinterpret_cast<PetscObject>(A), type, &same),
        "PetscObjectTypeCompare");
  return same;
}

/// Slots of the locally owned rows of an assembled seqaij or mpiaij matrix,
/// addressed by global row and column. A slot numbers the entries of the
/// diagonal part's value array first, then the off-diagonal part's
/// (mpiaij): [0, diagonal_size) and [diagonal_size, ...). Holds the CSR
/// arrays while it lives.
class AijPattern
{
public:
  /// Nothing usable (usable() false) for other types or a matrix without
  /// its final pattern (an mpiaij before its first assembly).
  explicit AijPattern(Mat A);

  bool usable() const { return _usable; }
  /// Owned rows [row_begin, row_end).
  PetscInt row_begin() const { return _r0; }
  PetscInt row_end() const { return _r1; }
  std::int64_t diagonal_size() const { return _diagonal_size; }

  /// Slot of global (row, col), row owned here; -2 outside the pattern.
  std::int64_t slot(PetscInt row, PetscInt col) const;
  /// Global column of a slot in row `row`; -1 when the slot is not in it.
  std::int64_t column(PetscInt row, std::int64_t slot) const;

private:
  bool _usable = false;
  PetscInt _r0 = 0, _r1 = 0, _c0 = 0, _c1 = 0, _num_off = 0;
  std::int64_t _diagonal_size = 0;
  const PetscInt* _garray = nullptr; // global column of each off-diagonal column
  std::unique_ptr<RowIJ> _diagonal, _off_diagonal;
};

/// The value arrays of a seqaij or mpiaij matrix, addressed by AijPattern
/// slots; handed back on destruction (before any MatSetValues, which may
/// reallocate them).
class AijValues
{
public:
  AijValues(Mat A, std::int64_t diagonal_size);
  double& operator[](std::int64_t slot)
  {
    return slot < _diagonal_size ? _diagonal->data[slot] : _off->data[slot - _diagonal_size];
  }
  double* diagonal() { return _diagonal->data; }
  double* off_diagonal() { return _off ? _off->data : nullptr; }

private:
  std::int64_t _diagonal_size;
  std::unique_ptr<Values> _diagonal, _off;
};

} // namespace textile::assembly

#include "preallocation.h"
#include "petsc_error.h"

#include <stdexcept>
#include <string>
#include <vector>

namespace textile::assembly
{
Mat create_preallocator(Mat base)
{
  MPI_Comm comm;
  check(PetscObjectGetComm(reinterpret_cast<PetscObject>(base), &comm), "PetscObjectGetComm");
  PetscInt m, n, M, N;
  check(MatGetLocalSize(base, &m, &n), "MatGetLocalSize");
  check(MatGetSize(base, &M, &N), "MatGetSize");
  Mat P;
  check(MatCreate(comm, &P), "MatCreate");
  check(MatSetType(P, MATPREALLOCATOR), "MatSetType");
  check(MatSetSizes(P, m, n, M, N), "MatSetSizes");
  check(MatSetUp(P), "MatSetUp");
  ISLocalToGlobalMapping rmap, cmap;
  check(MatGetLocalToGlobalMapping(base, &rmap, &cmap), "MatGetLocalToGlobalMapping");
  if (rmap and cmap)
    check(MatSetLocalToGlobalMapping(P, rmap, cmap), "MatSetLocalToGlobalMapping");
  // the base pattern, row by row (owned rows)
  PetscInt r0, r1;
  check(MatGetOwnershipRange(base, &r0, &r1), "MatGetOwnershipRange");
  std::vector<PetscScalar> zeros;
  for (PetscInt row = r0; row < r1; ++row)
  {
    PetscInt ncols;
    const PetscInt* cols;
    check(MatGetRow(base, row, &ncols, &cols, nullptr), "MatGetRow");
    zeros.assign(ncols, 0.0);
    check(MatSetValues(P, 1, &row, ncols, cols, zeros.data(), INSERT_VALUES), "MatSetValues");
    check(MatRestoreRow(base, row, &ncols, &cols, nullptr), "MatRestoreRow");
  }
  return P;
}

Mat preallocated_matrix(Mat P, Mat base)
{
  check(MatAssemblyBegin(P, MAT_FINAL_ASSEMBLY), "MatAssemblyBegin");
  check(MatAssemblyEnd(P, MAT_FINAL_ASSEMBLY), "MatAssemblyEnd");
  MPI_Comm comm;
  check(PetscObjectGetComm(reinterpret_cast<PetscObject>(base), &comm), "PetscObjectGetComm");
  PetscInt m, n, M, N;
  check(MatGetLocalSize(base, &m, &n), "MatGetLocalSize");
  check(MatGetSize(base, &M, &N), "MatGetSize");
  MatType type;
  check(MatGetType(base, &type), "MatGetType");
  Mat A;
  check(MatCreate(comm, &A), "MatCreate");
  check(MatSetType(A, type), "MatSetType");
  check(MatSetSizes(A, m, n, M, N), "MatSetSizes");
  check(MatPreallocatorPreallocate(P, PETSC_TRUE, A), "MatPreallocatorPreallocate");
  ISLocalToGlobalMapping rmap, cmap;
  check(MatGetLocalToGlobalMapping(base, &rmap, &cmap), "MatGetLocalToGlobalMapping");
  if (rmap and cmap)
    check(MatSetLocalToGlobalMapping(A, rmap, cmap), "MatSetLocalToGlobalMapping");
  // a coupling missed by the pattern costs a reallocation, not a failed run
  check(MatSetOption(A, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_FALSE), "MatSetOption");
  return A;
}
} // namespace textile::assembly

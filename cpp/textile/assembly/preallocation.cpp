#include "preallocation.h"
#include "petsc_error.h"

#include <stdexcept>
#include <string>
#include <vector>

namespace textile::assembly
{
namespace
{
/// A new matrix of `type` with the communicator and sizes of `like`.
Mat matrix_like(Mat like, MatType type)
{
  MPI_Comm comm;
  check(PetscObjectGetComm(reinterpret_cast<PetscObject>(like), &comm), "PetscObjectGetComm");
  PetscInt m, n, M, N;
  check(MatGetLocalSize(like, &m, &n), "MatGetLocalSize");
  check(MatGetSize(like, &M, &N), "MatGetSize");
  Mat A;
  check(MatCreate(comm, &A), "MatCreate");
  check(MatSetType(A, type), "MatSetType");
  check(MatSetSizes(A, m, n, M, N), "MatSetSizes");
  return A;
}

/// Give `A` the local-to-global maps of `like` (if it has them).
void copy_local_to_global(Mat like, Mat A)
{
  ISLocalToGlobalMapping rmap, cmap;
  check(MatGetLocalToGlobalMapping(like, &rmap, &cmap), "MatGetLocalToGlobalMapping");
  if (rmap and cmap)
    check(MatSetLocalToGlobalMapping(A, rmap, cmap), "MatSetLocalToGlobalMapping");
}
} // namespace

Mat create_preallocator(Mat base)
{
  Mat P = matrix_like(base, MATPREALLOCATOR);
  check(MatSetUp(P), "MatSetUp");
  copy_local_to_global(base, P);
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
  MatType type;
  check(MatGetType(base, &type), "MatGetType");
  Mat A = matrix_like(base, type);
  check(MatPreallocatorPreallocate(P, PETSC_TRUE, A), "MatPreallocatorPreallocate");
  copy_local_to_global(base, A);
  // a coupling missed by the pattern costs a reallocation, not a failed run
  check(MatSetOption(A, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_FALSE), "MatSetOption");
  return A;
}
} // namespace textile::assembly

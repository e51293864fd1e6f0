#include "absolute_product.h"
#include "petsc_error.h"

#include <cmath>
#include <stdexcept>

namespace textile::assembly
{
namespace
{
/// Replace the values of a sequential AIJ matrix by their absolute values.
void absolute_values(Mat B)
{
  MatInfo info;
  check(MatGetInfo(B, MAT_LOCAL, &info), "MatGetInfo");
  PetscScalar* v = nullptr;
  check(MatSeqAIJGetArray(B, &v), "MatSeqAIJGetArray");
  const auto n = static_cast<std::size_t>(info.nz_used);
  for (std::size_t k = 0; k < n; ++k)
    v[k] = std::abs(v[k]);
  check(MatSeqAIJRestoreArray(B, &v), "MatSeqAIJRestoreArray");
}
} // namespace

void absolute_product(Mat A, Vec x, Vec y)
{
  PetscBool seq = PETSC_FALSE, mpi = PETSC_FALSE;
  check(PetscObjectTypeCompare(reinterpret_cast<PetscObject>(A), MATSEQAIJ, &seq),
        "PetscObjectTypeCompare");
  check(PetscObjectTypeCompare(reinterpret_cast<PetscObject>(A), MATMPIAIJ, &mpi),
        "PetscObjectTypeCompare");
  if (!seq and !mpi)
    throw std::invalid_argument("absolute_product: A must be a SEQAIJ or MPIAIJ matrix");
  Mat B;
  check(MatDuplicate(A, MAT_COPY_VALUES, &B), "MatDuplicate");
  if (seq)
    absolute_values(B);
  else
  {
    Mat diag, offdiag;
    const PetscInt* colmap;
    check(MatMPIAIJGetSeqAIJ(B, &diag, &offdiag, &colmap), "MatMPIAIJGetSeqAIJ");
    absolute_values(diag);
    absolute_values(offdiag);
  }
  Vec xabs;
  check(VecDuplicate(x, &xabs), "VecDuplicate");
  check(VecCopy(x, xabs), "VecCopy");
  check(VecAbs(xabs), "VecAbs");
  check(MatMult(B, xabs, y), "MatMult");
  check(VecDestroy(&xabs), "VecDestroy");
  check(MatDestroy(&B), "MatDestroy");
}
} // namespace textile::assembly

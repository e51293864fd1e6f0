// PETSc (serial) for the unit tests that need it, and reading matrices back.
#pragma once

#include <gtest/gtest.h>
#include <petscmat.h>
#include <petscsys.h>

/// Started by the first test that needs it (starting MPI costs the other
/// tests of the program nothing then) and ended with the program.
class PetscEnvironment : public ::testing::Environment
{
public:
  static void require()
  {
    PetscBool up;
    PetscInitialized(&up);
    if (!up)
      PetscInitializeNoArguments();
  }
  void TearDown() override
  {
    PetscBool up;
    PetscInitialized(&up);
    if (up)
      PetscFinalize();
  }
};

// one registration for the whole test program (an inline variable)
[[maybe_unused]] inline ::testing::Environment* const petsc_environment
    = ::testing::AddGlobalTestEnvironment(new PetscEnvironment);

/// f(row, column, value) for every stored entry of an assembled sequential
/// matrix, row by row.
template <typename F>
void for_each_entry(Mat A, F f)
{
  PetscInt m, n;
  MatGetSize(A, &m, &n);
  for (PetscInt r = 0; r < m; ++r)
  {
    PetscInt ncols;
    const PetscInt* cols;
    const PetscScalar* vals;
    MatGetRow(A, r, &ncols, &cols, &vals);
    for (PetscInt k = 0; k < ncols; ++k)
      f(r, cols[k], vals[k]);
    MatRestoreRow(A, r, &ncols, &cols, &vals);
  }
}

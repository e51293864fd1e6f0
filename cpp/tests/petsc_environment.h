// PETSc (serial) for the unit tests that need it.
#pragma once

#include <gtest/gtest.h>
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

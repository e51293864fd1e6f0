// PETSc error codes turned into C++ exceptions.
#pragma once

#include <petscsys.h>

#include <stdexcept>
#include <string>

namespace textile::assembly
{
/// Throws std::runtime_error naming the call when a PETSc call fails: an
/// unchecked failure (e.g. of MatSetValues) would leave silent zeros.
inline void check(PetscErrorCode ierr, const char* what)
{
  if (ierr != 0)
    throw std::runtime_error(std::string(what) + " failed with PETSc error "
                             + std::to_string(ierr));
}
} // namespace textile::assembly

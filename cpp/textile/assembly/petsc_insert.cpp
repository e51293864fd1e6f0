#include "petsc_insert.h"
#include "petsc_error.h"

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

void add_diagonal(Mat A, std::span<const std::int32_t> rows, double value)
{
  for (std::int32_t i : rows)
  {
    if (i < 0)
      continue;
    check(MatSetValuesLocal(A, 1, &i, 1, &i, &value, ADD_VALUES), "MatSetValuesLocal");
  }
}
} // namespace textile::assembly

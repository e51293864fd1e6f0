// The rebuilt matrix's pattern: the base's rows plus the declared blocks,
// each entry once, zeros, and only the base after a rebuild.
#include <textile/assembly/sparsity_pattern.h>

#include "petsc_environment.h"

#include <gtest/gtest.h>
#include <petscmat.h>

#include <algorithm>
#include <set>
#include <vector>

using textile::assembly::SparsityPattern;

namespace
{
/// Columns of each row of an assembled sequential matrix, and whether any
/// stored value is nonzero.
std::vector<std::set<PetscInt>> rows_of(Mat A, bool& any_nonzero)
{
  PetscInt m, n;
  MatGetSize(A, &m, &n);
  std::vector<std::set<PetscInt>> rows(m);
  any_nonzero = false;
  for_each_entry(A,
                 [&](PetscInt r, PetscInt c, PetscScalar v)
                 {
                   rows[r].insert(c);
                   any_nonzero = any_nonzero or v != 0.0;
                 });
  return rows;
}
} // namespace

TEST(SparsityPattern, BaseRowsPlusDeclaredBlocks)
{
  PetscEnvironment::require();
  const int n = 12;
  // base: tridiagonal, with values
  Mat base;
  MatCreateSeqAIJ(PETSC_COMM_SELF, n, n, 3, nullptr, &base);
  std::vector<std::set<PetscInt>> expected(n);
  for (PetscInt i = 0; i < n; ++i)
    for (PetscInt j = std::max<PetscInt>(0, i - 1); j <= std::min<PetscInt>(n - 1, i + 1); ++j)
    {
      MatSetValue(base, i, j, 1.0 + i + j, INSERT_VALUES);
      expected[i].insert(j);
    }
  MatAssemblyBegin(base, MAT_FINAL_ASSEMBLY);
  MatAssemblyEnd(base, MAT_FINAL_ASSEMBLY);

  SparsityPattern pattern(base);
  EXPECT_EQ(pattern.base_size(), 3u * n - 2);
  // two overlapping blocks; -1 (a constrained unknown) is skipped
  const std::vector<std::int32_t> rows_a = {2, -1, 9}, cols_a = {0, 9, -1, 5};
  const std::vector<std::int32_t> rows_b = {9, 10}, cols_b = {5, 2, 11};
  pattern.add(rows_a, cols_a);
  pattern.add(rows_b, cols_b);
  for (const auto& [rows, cols] : {std::pair{rows_a, cols_a}, std::pair{rows_b, cols_b}})
    for (const auto r : rows)
      for (const auto c : cols)
        if (r >= 0 and c >= 0)
          expected[r].insert(c);

  Mat A = pattern.create_matrix(base);
  bool any_nonzero;
  EXPECT_EQ(rows_of(A, any_nonzero), expected);
  EXPECT_FALSE(any_nonzero);
  // an entry outside the pattern is still accepted (a reallocation)
  EXPECT_EQ(MatSetValue(A, 0, 7, 1.0, ADD_VALUES), 0);
  MatDestroy(&A);

  // the declared blocks are forgotten: the next matrix is the base's pattern
  Mat B = pattern.create_matrix(base);
  std::vector<std::set<PetscInt>> base_only(n);
  for (PetscInt i = 0; i < n; ++i)
    for (PetscInt j = std::max<PetscInt>(0, i - 1); j <= std::min<PetscInt>(n - 1, i + 1); ++j)
      base_only[i].insert(j);
  EXPECT_EQ(rows_of(B, any_nonzero), base_only);
  MatDestroy(&B);
  MatDestroy(&base);
}

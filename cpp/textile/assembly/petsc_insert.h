// The single place where local blocks enter a PETSc matrix.
#pragma once

#include <petscmat.h>

#include <cstdint>
#include <span>

namespace textile::assembly
{

/// A[rows, cols] += values (row-major), in the matrix's local numbering
/// (its local-to-global map). Negative indices are skipped by PETSc: that
/// is how constrained (Dirichlet) dofs are kept out of the tangent.
/// Throws std::runtime_error on a PETSc error.
void add_block(Mat A, std::span<const std::int32_t> rows, std::span<const std::int32_t> cols,
               std::span<const double> values);

/// A[i, i] += value for every local index i in rows (negative skipped).
void add_diagonal(Mat A, std::span<const std::int32_t> rows, double value);

} // namespace textile::assembly

// |A| |x|: the size of the terms that make up A x.
//
// The round-off of a residual assembled from element contributions is of
// the order of eps times the sum of the magnitudes of those contributions;
// for internal forces that are (locally) linear in the unknowns this is
// eps |K| |q|, with K the tangent and q the unknowns as the kernels see
// them (positions, not displacements). The solver's convergence test uses
// it as the round-off floor of each field's residual.
#pragma once

#include <petscmat.h>
#include <petscvec.h>

namespace textile::assembly
{

/// y = |A| |x| (entrywise absolute values). A is an assembled AIJ matrix
/// (sequential or MPI); x and y are compatible with A's columns and rows.
void absolute_product(Mat A, Vec x, Vec y);

} // namespace textile::assembly

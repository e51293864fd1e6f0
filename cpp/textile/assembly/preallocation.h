// Matrices whose nonzero pattern grows with the contact set.
//
// Contact couples unknowns that change from one detection pass to the next
// and that need not be local to one rank, so their entries cannot be
// declared in the dolfinx sparsity pattern built once. When the couplings
// change, the system matrix is rebuilt: the base pattern (beams, matrix
// block, junctions) plus the new couplings, preallocated exactly through a
// PETSc MATPREALLOCATOR, so assembly never reallocates.
#pragma once

#include <petscmat.h>

namespace textile::assembly
{

/// A MATPREALLOCATOR with the layout and local-to-global map of `base`,
/// holding base's nonzero pattern. Insert more entries with MatSetValues
/// (global indices), then call preallocated_matrix. The caller owns it.
Mat create_preallocator(Mat base);

/// A new AIJ matrix (zero entries) with the pattern collected in
/// `preallocator`, the layout, local-to-global map and options of `base`.
/// Assembles the preallocator. The caller owns the result.
Mat preallocated_matrix(Mat preallocator, Mat base);

} // namespace textile::assembly

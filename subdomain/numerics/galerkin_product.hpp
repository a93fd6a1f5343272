#pragma once
// The Galerkin product of the algebraic multigrid's setup (algebraic_multigrid.hpp): the coarse
// matrix P' A P from a level's matrix A and its prolongator P stored by blocks.

#include "numerics/block_sparse_matrix.hpp"

namespace robin {

/// The Galerkin product C = P' A P of the symmetric `matrix` A (both triangles stored, its rows
/// and columns grouped as P's rows) and `prolongator` P, both triangles of C in compressed rows.
/// Block by block: for each block row i of A, (A P)_i = sum_j A_ij P_j by a sparse accumulator
/// over the coarse blocks, then C_IJ += P_iI' (A P)_iJ for the blocks J <= I only; C's upper
/// triangle is the mirror of its lower (exactly symmetric), the diagonal blocks symmetrized.
/// (A P) is never held whole. Throws std::invalid_argument when the sizes differ.
RowMajorSparseMatrix galerkin_product(const RowMajorSparseMatrix& matrix,
                                      const BlockSparseMatrix<double>& prolongator);

}  // namespace robin

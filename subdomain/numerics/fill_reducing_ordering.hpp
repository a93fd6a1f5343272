#pragma once
// Fill-reducing elimination order of a body's stiffness, computed on its node graph.
//
// The d displacement components of a node couple to exactly the same unknowns, so their columns
// of K have the same pattern: they are one supervariable. The ordering is computed on the graph
// of the supervariables (d times fewer vertices, d^2 times fewer edges than the graph of the
// unknowns) and expanded back, each supervariable's unknowns kept together in their own order.
// Eliminating a supervariable's unknowns one after the other creates no fill beyond what the
// node-level elimination does, so the order is as good as one computed on the unknowns, at a
// fraction of the cost of AMD and METIS on the full graph.
//
// When the unknowns' positions are known (a body's mesh), the supervariable graph is ordered by
// geometric nested dissection (geometric_dissection.hpp) with a constrained minimum-degree order
// (CAMD) inside each set; otherwise by AMD. METIS (nested dissection by multilevel partitioning)
// costs far more and pays off only through a cheaper numerical factorization, so it is computed
// too only when the factorization with the first order needs many floating-point operations per
// entry of the graph (the unknowns' flops estimated from the graph's): more than 2e4 after AMD
// (large plane bodies, solid bodies) and after the geometric dissection of a graded mesh (whose
// straight cuts cross the refined zone), more than 1e5 after the geometric dissection of a
// quasi-uniform mesh (large solid bodies). The order with fewer flops is kept
// (docs/benchmarks.md).

#include <Eigen/Core>
#include <string>
#include <vector>

#include "numerics/elasticity.hpp"

struct cholmod_common_struct;

namespace robin {

/// The elimination order of the symmetric matrix whose lower triangle `matrix` holds (its upper
/// triangle is not read): order[k] is the unknown eliminated k-th. The unknowns other than
/// `trailing` come first, in the fill-reducing order of the matrix restricted to them (above);
/// then `trailing`, in the given order. Supervariables are found among consecutive unknowns
/// (the components of a node are numbered together). `unknown_points`: the position of each
/// unknown's node (one per unknown), or empty when unknown. `common` is CHOLMOD's workspace; its
/// ordering settings are restored on return. Throws std::invalid_argument naming `body_name`
/// when a trailing unknown is out of range or repeated, std::bad_alloc when CHOLMOD runs out of
/// memory, std::runtime_error when it fails otherwise; std::invalid_argument when
/// unknown_points is neither empty nor one per unknown.
std::vector<int> fill_reducing_ordering(const SparseMatrix& matrix,
                                        const std::vector<int>& trailing,
                                        const std::vector<Eigen::Vector3d>& unknown_points,
                                        cholmod_common_struct& common,
                                        const std::string& body_name);

}  // namespace robin

#pragma once
// The columns of history.csv, shared by the run's history.csv and the load steps' history
// (steps/history.csv, which prefixes step and load_factor). docs/outputs.md describes every
// column: the joint state's residuals, per body its closed rows (active1..activeN) and contact
// QP iterations (qp_iterations1..N), the iteration's wall time, the largest residual of each
// obstacle sequence's complete state ("robin" only; empty otherwise), and what the stopping
// test compared with the tolerance (stopping_residual = IterationRecord::progress).

#include <ostream>

#include "coupling/robin_iteration.hpp"

namespace robin {

/// "iteration,obstacle_change,...,tolerance" for `bodies` bodies, without a newline.
void write_history_header(std::ostream& stream, std::size_t bodies);

/// One row of the columns of write_history_header, without a newline.
void write_history_row(std::ostream& stream, const IterationRecord& record, bool either_sequence,
                       double tolerance);

/// The number of bodies of a history (2 for an empty one).
std::size_t history_body_count(const std::vector<IterationRecord>& history);

}  // namespace robin

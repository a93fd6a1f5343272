#include "coupling/history_rows.hpp"

namespace robin {

void write_history_header(std::ostream& stream, std::size_t bodies) {
  stream << "iteration,obstacle_change,penetration,force_balance,complementarity,correction,";
  for (const char* name : {"active", "qp_iterations"}) {
    for (std::size_t body = 1; body <= bodies; ++body) stream << name << body << ',';
  }
  stream << "seconds,sequence1,sequence2,stopping_residual,tolerance";
}

void write_history_row(std::ostream& stream, const IterationRecord& record, bool either_sequence,
                       double tolerance) {
  stream << record.iteration << ',' << record.obstacle_change << ',' << record.penetration << ','
         << record.force_balance << ',' << record.complementarity << ',' << record.correction;
  for (const std::vector<int>* counts : {&record.active, &record.qp_iterations}) {
    for (const int count : *counts) stream << ',' << count;
  }
  stream << ',' << record.seconds;
  for (std::size_t k = 0; k < 2; ++k) {
    stream << ',';
    if (k < record.sequences.size()) stream << record.sequences[k].largest();
  }
  stream << ',' << record.progress(either_sequence) << ',' << tolerance;
}

std::size_t history_body_count(const std::vector<IterationRecord>& history) {
  return history.empty() ? 2 : history.front().active.size();
}

}  // namespace robin

#include "coupling/port_recovery.hpp"

#include <algorithm>
#include <utility>

namespace robin {

RecoverablePorts::RecoverablePorts(const std::vector<SubdomainPort*>& ports,
                                   const CaseDefinition& loaded, ServerReplacement replacement,
                                   std::function<void(const std::string&)> report)
    : ports_(ports),
      replaced_timings_(ports.size()),
      loaded_(loaded),
      replacement_(std::move(replacement)),
      report_(std::move(report)),
      interfaces_(ports.size()) {}

PortTimings RecoverablePorts::timings(int body) const {
  PortTimings sum = replaced_timings_.at(static_cast<std::size_t>(body));
  const PortTimings& current = ports_.at(static_cast<std::size_t>(body))->timings();
  sum.compute_seconds += current.compute_seconds;
  sum.round_trip_seconds += current.round_trip_seconds;
  sum.bytes_sent += current.bytes_sent;
  sum.bytes_received += current.bytes_received;
  return sum;
}

void RecoverablePorts::restore_body(int body) {
  const auto index = static_cast<std::size_t>(body);
  // a body not set up yet (its setup was under way, or its mesh not in yet) is set up by the
  // setup stage when it runs again
  if (!interfaces_[index]) return;
  SubdomainPort& port = *ports_[index];
  const std::string& name = loaded_.bodies[index].definition.name;
  if (report_) report_("setting body '" + name + "' up again on " + port.describe());
  interfaces_[index] = port.setup(loaded_.bodies[index], loaded_.solver);
  if (operators_ != nullptr) port.assign_contact(operators_->at(index));
  if (load_factor_) port.set_load_factor(*load_factor_);
}

void RecoverablePorts::recover(const PortError& error) {
  std::string failure = error.what();
  const std::size_t count = ports_.size();
  for (;;) {
    std::vector<bool> lost(count, false);
    if (replacement_) {
      for (std::size_t body = 0; body < count; ++body) {
        lost[body] = replacement_.lost(static_cast<int>(body));
      }
    }
    if (std::find(lost.begin(), lost.end(), true) == lost.end()) throw PortError(failure);
    for (std::size_t body = 0; body < count; ++body) {
      ports_[body]->abandon_request();
      // throws when the server cannot be replaced: the run fails with that message
      if (!lost[body]) continue;
      const PortTimings& old = ports_[body]->timings();
      PortTimings& sum = replaced_timings_[body];
      sum.compute_seconds += old.compute_seconds;
      sum.round_trip_seconds += old.round_trip_seconds;
      sum.bytes_sent += old.bytes_sent;
      sum.bytes_received += old.bytes_received;
      ports_[body] = replacement_.replace(static_cast<int>(body), failure);
    }
    try {
      for (std::size_t body = 0; body < count; ++body) {
        if (lost[body]) {
          restore_body(static_cast<int>(body));
        } else if (operators_ != nullptr) {
          ports_[body]->assign_contact(operators_->at(body));
        }
      }
      return;
    } catch (const PortError& again) {  // lost again while being restored
      failure = again.what();
    }
  }
}

}  // namespace robin
